#include "adapters/daemon/dds_publisher.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <memory>

#include "adapters/daemon/samples.hpp"
#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/port/steady_time.hpp"

namespace dnbridge::daemon {

WallClock::WallClock() {
  const auto wall = std::chrono::system_clock::now().time_since_epoch();
  const auto mono = std::chrono::steady_clock::now().time_since_epoch();
  offset_ = std::chrono::duration_cast<std::chrono::nanoseconds>(wall) -
            std::chrono::duration_cast<std::chrono::nanoseconds>(mono);
}

dds::Timestamp WallClock::to_wall(TimePoint monotonic) const {
  return dds::Timestamp(monotonic.time_since_epoch() + offset_);
}

DdsPublisher::~DdsPublisher() = default;

DdsPublisher::DdsPublisher(const dds::Participant& participant, std::string rack,
                           Duration state_deadline, Logger log,
                           std::span<const ProfileTopics> profiles)
    : rack_(std::move(rack)),
      log_(std::move(log)),
      partition_{dds::rack_partition(rack_)},
      node_topic_(participant),
      port_topic_(participant),
      request_topic_(participant),
      reply_topic_(participant),
      node_writer_(participant, node_topic_, dds::state_writer_qos(state_deadline)),
      port_writer_(participant, port_topic_, dds::state_writer_qos(state_deadline)),
      reply_writer_(participant, reply_topic_, dds::reply_writer_qos(partition_)),
      scan_(unless_denied(log_, "the bus scan (dnbridge/BusScanRequest, BusScanReply)",
                          [&] {
                            return Service<dnbridge_BusScanRequest, dnbridge_BusScanReply>(
                                participant, dds::scan_reply_writer_qos(partition_));
                          })),
      reload_(unless_denied(log_, "reload over DDS (dnbridge/ReloadRequest, ReloadReply)",
                            [&] {
                              return Service<dnbridge_ReloadRequest, dnbridge_ReloadReply>(
                                  participant, dds::scan_reply_writer_qos(partition_));
                            })),
      reply_out_("dds reply out", kReplyBacklog) {
  const dds::Qos qos = dds::state_writer_qos(state_deadline);
  for (const ProfileTopics& profile : profiles) {
    state_topics_.push_back(profile.make_state(participant, qos, log_));
  }
}

StateTopic* DdsPublisher::state_topic(std::string_view profile) const {
  for (const auto& t : state_topics_) {
    if (t->profile() == profile) return t.get();
  }
  return nullptr;
}

void DdsPublisher::check_state(Status s, const char* what) {
  if (!check(s, what)) state_write_failures_.fetch_add(1, std::memory_order_relaxed);
}

bool DdsPublisher::check(Status s, const char* what) {
  if (s) return true;
  std::lock_guard lock(log_mutex_);
  error_limit_.error(log_, port::steady_now(), "writing {} failed: {}", what, s.error().message());
  return false;
}

void DdsPublisher::note_written(const std::string& port, std::uint8_t mac, StateTopic& topic) {
  std::lock_guard lock(mutex_);
  written_[port][mac] = &topic;
}

void DdsPublisher::node_state(const std::string& port, const rack::NodeView& node,
                              TimePoint source_time) {
  StateTopic* topic = state_topic(node.profile);
  if (!topic) return;
  note_written(port, node.mac.value(), *topic);
  check_state(topic->write(rack_, port, node, clock_.to_wall(source_time)), topic->name());
}

void DdsPublisher::node_status(const std::string& port, const rack::NodeView& node,
                               const port::NodeStatusView& status, TimePoint source_time) {
  StateTopic* topic = state_topic(node.profile);
  if (!topic) return;
  note_written(port, node.mac.value(), *topic);
  dds::Owned<dnbridge_NodeStatus> sample;
  topic->fill_status(*sample, rack_, port, node, status);
  check_state(node_writer_.write(*sample, clock_.to_wall(source_time)), "NodeStatus");
}

void DdsPublisher::port_status(const port::PortStatusView& status, TimePoint source_time) {
  dds::Owned<dnbridge_PortStatus> sample;
  fill_port_status(*sample, rack_, status);
  sample->replies_undelivered = replies_undelivered(status.port);
  sample->max_commander_lease_ms = max_commander_lease_ms_.load(std::memory_order_relaxed);
  sample->commanders_refused = commanders_refused_.load(std::memory_order_relaxed);
  sample->endpoints_unmatched = endpoints_unmatched_.load(std::memory_order_relaxed);
  check_state(port_writer_.write(*sample, clock_.to_wall(source_time)), "PortStatus");
}

void DdsPublisher::explicit_reply(const std::string& port, const rack::ExplicitAnswer& answer) {
  auto sample = std::make_shared<dds::Owned<dnbridge_ExplicitReply>>();
  fill_explicit_reply(**sample, answer);
  const bool queued = reply_out_.post([this, sample, port] {
    if (!check(reply_writer_.write(**sample), "ExplicitReply")) undelivered(port);
  });
  if (!queued) undelivered(port);
}

void DdsPublisher::bus_scan_reply(const std::string& port, const port::BusScanAnswer& answer) {
  auto sample = std::make_shared<dds::Owned<dnbridge_BusScanReply>>();
  fill_bus_scan_reply(**sample, rack_, port, answer);
  const bool queued = reply_out_.post([this, sample, port] {
    if (!scan_ || !check(scan_->writer.write(**sample), "BusScanReply")) undelivered(port);
  });
  if (!queued) undelivered(port);
}

void DdsPublisher::reload_reply(const ReloadCall& call, const ReloadReport& report) {
  auto sample = std::make_shared<dds::Owned<dnbridge_ReloadReply>>();
  fill_reload_reply(**sample, rack_, call, report);
  // Counted with no port's replies: a reload is the rack's.
  const bool queued = reply_out_.post([this, sample] {
    if (!reload_ || !check(reload_->writer.write(**sample), "ReloadReply")) undelivered({});
  });
  if (!queued) undelivered({});
}

void DdsPublisher::undelivered(const std::string& port) {
  std::lock_guard lock(mutex_);
  ++undelivered_[port];
}

std::uint64_t DdsPublisher::replies_undelivered(const std::string& port) const {
  std::lock_guard lock(mutex_);
  auto it = undelivered_.find(port);
  return it == undelivered_.end() ? 0 : it->second;
}

void DdsPublisher::release_node(const std::string& port, std::uint8_t mac, StateTopic& topic,
                                bool dispose) {
  const auto now = dds::dds_now();
  const auto node_key = key_of<dnbridge_NodeStatus>(rack_, port, mac);
  const std::string what = topic.name();
  if (dispose) check_state(topic.dispose(rack_, port, mac, now), (what + " disposal").c_str());
  check_state(topic.unregister(rack_, port, mac, now), (what + " unregistration").c_str());
  if (dispose) check_state(node_writer_.dispose(*node_key, now), "NodeStatus disposal");
  check_state(node_writer_.unregister_instance(*node_key, now), "NodeStatus unregistration");
}

void DdsPublisher::node_removed(const std::string& port, devicenet::MacId mac) {
  StateTopic* topic = nullptr;
  {
    std::lock_guard lock(mutex_);
    auto& macs = written_[port];
    if (auto it = macs.find(mac.value()); it != macs.end()) {
      topic = it->second;
      macs.erase(it);
    }
  }
  // Disposed: the node is no longer the rack's (or no longer of that
  // profile), which unregistering (the bridge gone) would not say. Only
  // what was written.
  if (topic) release_node(port, mac.value(), *topic, true);
}

void DdsPublisher::port_stopped(const std::string& port) {
  // Unregister, never dispose: the last samples (online false, stopped) stay
  // what late readers see until the bridge is back.
  std::map<std::uint8_t, StateTopic*> macs;
  {
    std::lock_guard lock(mutex_);
    macs = std::move(written_[port]);
    written_.erase(port);
  }
  for (const auto& [mac, topic] : macs) release_node(port, mac, *topic, false);
  dds::Owned<dnbridge_PortStatus> port_key;
  dds::set_string(port_key->rack, rack_);
  dds::set_string(port_key->port, port);
  check_state(port_writer_.unregister_instance(*port_key, dds::dds_now()),
              "PortStatus unregistration");
}

}  // namespace dnbridge::daemon

namespace dnbridge::daemon {

void DdsPublisher::flush(Duration timeout) {
  // One deadline for them all: a reader that died without leaving stays
  // matched until its lease ends, and each wait would otherwise take all of
  // `timeout` for it.
  const TimePoint deadline = port::steady_now() + timeout;
  auto left = [&] { return std::max(Duration::zero(), deadline - port::steady_now()); };
  (void)reply_out_.drain(left());
  for (const auto& topic : state_topics_) topic->wait_for_acks(left());
  (void)node_writer_.wait_for_acks(left());
  (void)port_writer_.wait_for_acks(left());
  (void)reply_writer_.wait_for_acks(left());
  if (scan_) (void)scan_->writer.wait_for_acks(left());
  if (reload_) (void)reload_->writer.wait_for_acks(left());
}

}  // namespace dnbridge::daemon
