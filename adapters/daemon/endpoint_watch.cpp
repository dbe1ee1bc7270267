#include "adapters/daemon/endpoint_watch.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

#include "adapters/dds/topics.hpp"
#include "adapters/port/steady_time.hpp"
#include "adapters/port/thread_name.hpp"

namespace dnbridge::daemon {
namespace {

enum Token : dds::WaitSet::Token { kParticipants = 1, kPublications, kSubscriptions, kStop };

bool is_command_topic(std::string_view topic) {
  return topic == dds::TopicTraits<dnbridge_PumpCommand>::kName ||
         topic == dds::TopicTraits<dnbridge_DeviceCommand>::kName;
}

long long ms_of(Duration d) { return std::chrono::duration_cast<milliseconds>(d).count(); }

std::string lease_text(const std::optional<Duration>& d) {
  return d ? fmt::format("{} ms", ms_of(*d)) : std::string("infinite");
}

}  // namespace

EndpointWatch::EndpointWatch(const dds::Participant& participant, Settings settings, Logger log)
    : participant_(participant),
      settings_(std::move(settings)),
      log_(std::move(log)),
      rack_partition_{dds::rack_partition(settings_.rack)},
      participants_reader_(participant),
      endpoints_reader_(participant),
      stop_(participant),
      waitset_(participant) {
  dds_guid_t g{};
  if (dds_get_guid(participant.handle(), &g) == DDS_RETCODE_OK) {
    std::memcpy(self_.data(), g.v, self_.size());
  }
  // The bridge's own topics exist by now: what is discovered is compared
  // with their types from the first sample on.
  learn_types(dds::local_endpoints(participant));
  waitset_.attach(participants_reader_, kParticipants);
  waitset_.attach(endpoints_reader_.publications(), kPublications);
  waitset_.attach(endpoints_reader_.subscriptions(), kSubscriptions);
  waitset_.attach(stop_, kStop);
}

EndpointWatch::~EndpointWatch() { stop(); }

void EndpointWatch::start() {
  thread_ = std::thread([this] { run(); });
  port::name_thread(thread_, "dds endpoints");
}

void EndpointWatch::stop() {
  if (!thread_.joinable()) return;
  (void)stop_.trigger();
  thread_.join();
}

void EndpointWatch::run() {
  TimePoint next_look = port::steady_now();
  for (;;) {
    const TimePoint now = port::steady_now();
    auto triggered = waitset_.wait(std::max(Duration::zero(), next_look - now));
    if (!triggered) {
      log_.error("waiting for discovery failed: {}", triggered.error().message());
      continue;
    }
    if (std::find(triggered->begin(), triggered->end(), kStop) != triggered->end()) return;
    take(port::steady_now());
    if (port::steady_now() >= next_look) {
      look(port::steady_now());
      next_look = port::steady_now() + settings_.period;
    }
  }
}

const dds::TypeInfo* EndpointWatch::type_of(std::string_view topic) {
  auto it = types_.find(topic);
  return it == types_.end() ? nullptr : it->second.get();
}

void EndpointWatch::take(TimePoint now) {
  if (auto ps = participants_reader_.take()) {
    for (auto& p : *ps) {
      dds::Guid g{};
      std::memcpy(g.data(), p.guid.data(), g.size());
      if (p.alive) {
        participants_[g] = std::move(p);
      } else {
        participants_.erase(g);
      }
    }
  }
  auto es = endpoints_reader_.take([this](std::string_view topic) { return type_of(topic); });
  if (!es) {
    log_.error("taking discovered endpoints failed: {}", es.error().message());
    return;
  }
  for (auto& e : *es) {
    if (!e.alive) {
      remotes_.erase(e.guid);
      continue;
    }
    if (e.participant == self_) continue;
    auto [it, added] = remotes_.try_emplace(e.guid, Remote{e, now, {}});
    if (!added) it->second.endpoint = std::move(e);
  }
}

std::string EndpointWatch::who(const dds::DiscoveredEndpoint& e) const {
  std::string s = fmt::format("{} {} {} (participant {}", e.topic, e.writer ? "writer" : "reader",
                              dds::to_string(e.guid), dds::to_string(e.participant));
  if (auto it = participants_.find(e.participant); it != participants_.end()) {
    const auto& p = it->second;
    if (!p.name.empty()) s += fmt::format(" \"{}\"", p.name);
    const std::string host = dds::user_data_field(p.user_data, "host");
    if (!host.empty()) s += fmt::format(" on host {}", host);
    const std::string pid = dds::user_data_field(p.user_data, "pid");
    if (!pid.empty()) s += fmt::format(", pid {}", pid);
    s += fmt::format(", participant lease {}", lease_text(p.lease));
  }
  return s + ")";
}

std::string EndpointWatch::why_unmatched(const Remote& r,
                                         const std::vector<const dds::LocalEndpoint*>& by,
                                         bool& commander) const {
  const auto& e = r.endpoint;
  commander = false;
  if (e.writer && is_command_topic(e.topic)) {
    // A command reader missing it: it does not command that reader's nodes.
    commander = true;
    if (!e.lease || *e.lease > settings_.max_commander_lease) {
      return fmt::format(
          "offers a liveliness lease of {}; rack {} takes commands only from writers offering at "
          "most {} ms (max_commander_lease_ms): it commands nothing here. Set the command "
          "writer's liveliness lease (see the data-model guide)",
          lease_text(e.lease), settings_.rack, ms_of(settings_.max_commander_lease));
    }
    std::vector<std::string> refreshes;
    for (const auto* l : by) {
      if (!l->deadline || (e.deadline && *e.deadline <= *l->deadline)) continue;
      const auto ms = static_cast<std::uint32_t>(ms_of(*l->deadline));
      const std::string nodes =
          settings_.nodes_with_refresh ? settings_.nodes_with_refresh(ms) : std::string{};
      std::string refresh = fmt::format("command_refresh_ms = {}{}", ms,
                                        nodes.empty() ? "" : fmt::format(" ({})", nodes));
      // A node's own reader has its class's deadline: said once.
      if (std::find(refreshes.begin(), refreshes.end(), refresh) == refreshes.end()) {
        refreshes.push_back(std::move(refresh));
      }
    }
    if (!refreshes.empty()) {
      std::string list;
      for (const auto& x : refreshes) list += (list.empty() ? "" : "; ") + x;
      return fmt::format(
          "offers {}; it does not command the nodes with {}: their commands are taken only from "
          "writers offering a deadline of at most their command refresh, and written that often",
          e.deadline ? fmt::format("a deadline of {} ms", ms_of(*e.deadline))
                     : std::string("no deadline"),
          list);
    }
  }
  if (e.same_type == false) {
    return fmt::format(
        "its type \"{}\" differs from the bridge's in its XTypes type information (built from "
        "another version of dnbridge.idl? the data-model guide's \"Types and generators\"), or "
        "its QoS is incompatible",
        e.type_name);
  }
  return fmt::format(
      "its type \"{}\" or its QoS is incompatible with the bridge's (the data-model guide's "
      "QoS table)",
      e.type_name);
}

void EndpointWatch::learn_types(const std::vector<dds::LocalEndpoint>& locals) {
  for (const auto& l : locals) {
    if (types_.count(l.topic) != 0) continue;
    if (const dds_entity_t topic = dds_get_topic(l.handle); topic > 0) {
      types_.emplace(l.topic, std::make_unique<dds::TypeInfo>(topic));
    }
  }
}

bool EndpointWatch::serves_nodes(const dds::LocalEndpoint& l) const {
  if (l.writer || !is_command_topic(l.topic) || !l.deadline) return true;
  const auto ms = static_cast<std::uint32_t>(ms_of(*l.deadline));
  return !settings_.nodes_with_refresh || !settings_.nodes_with_refresh(ms).empty();
}

void EndpointWatch::look(TimePoint now) {
  const std::vector<dds::LocalEndpoint> locals = dds::local_endpoints(participant_);
  learn_types(locals);
  std::uint32_t refused = 0;
  std::uint32_t unmatched = 0;
  for (auto& [guid, r] : remotes_) {
    const auto& e = r.endpoint;
    std::vector<const dds::LocalEndpoint*> relevant;
    std::vector<const dds::LocalEndpoint*> missing;
    for (const auto& l : locals) {
      if (l.topic != e.topic || l.writer == e.writer) continue;
      if (!dds::partitions_meet(l.partitions, e.partitions)) continue;
      if (!serves_nodes(l)) continue;  // a command reader of a refresh no node has now
      relevant.push_back(&l);
      if (std::find(l.matched.begin(), l.matched.end(), guid) == l.matched.end()) {
        missing.push_back(&l);
      }
    }
    if (relevant.empty()) continue;  // not one of the bridge's topics, or not for this rack
    if (missing.empty()) {
      if (!r.reported.empty()) {
        log_.info("{}: now matches the bridge", who(e));
        r.reported.clear();
      }
      continue;
    }
    if (now - r.first_seen < settings_.grace) continue;
    bool commander = false;
    std::string why = why_unmatched(r, missing, commander);
    // A command writer matched by some of the command readers commands their
    // nodes: said once, not counted as refused.
    const bool partly = commander && missing.size() < relevant.size();
    if (!partly) ++(commander ? refused : unmatched);
    if (why == r.reported) continue;
    const Logger log = log_.with("DDS_GUID", dds::to_string(guid));
    if (partly) {
      log.info("{}: {}", who(e), why);
    } else {
      log.warn("{}: {}: {}", who(e),
               commander ? "refused as a commander" : "does not match the bridge", why);
    }
    r.reported = std::move(why);
  }
  const bool refused_changed = refused != commanders_refused_.exchange(refused);
  const bool unmatched_changed = unmatched != endpoints_unmatched_.exchange(unmatched);
  if ((refused_changed || unmatched_changed) && settings_.counted) {
    settings_.counted(refused, unmatched);
  }
}

}  // namespace dnbridge::daemon
