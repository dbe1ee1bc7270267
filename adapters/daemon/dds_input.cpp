#include "adapters/daemon/dds_input.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "adapters/daemon/samples.hpp"
#include "adapters/dds/fields.hpp"
#include "adapters/port/steady_time.hpp"
#include "adapters/port/thread_name.hpp"

namespace dnbridge::daemon {
namespace {

enum Token : dds::WaitSet::Token {
  kCommandsHeld = 1,
  kRequests = 2,
  kStop = 3,
  kScanRequests = 4,
  kReloadRequests = 5,
  kLogWaiting = 6,
  kSilenced = 7,
};

// A command stamped further ahead of this host's clock is reported.
constexpr Duration kClockSkewReported = seconds(1);

// Commands are not taken again sooner than this after a take: under a flood
// each node's newest command is applied once per hold-off, at most 1 ms late;
// one that comes alone is taken at once, on Cyclone's thread.
constexpr Duration kCommandHoldoff = milliseconds(1);

// Samples taken at a time.
constexpr std::size_t kBatch = 32;

// Requests taken before the commands are looked at again.
constexpr std::size_t kRequestBatches = 4;

// A request serialized in more bytes than this is dropped unanswered. A
// reply carries its requester name and may quote its port name, and the
// reply writer's history (256 replies, dds::kReplyHistory) must stay far
// below what Cyclone lets a writer hold unacknowledged (participant.cpp).
// The largest request the bridge serves (512 bytes of data, names of 100
// characters) takes under 900 bytes.
constexpr std::size_t kMaxRequestBytes = 2048;

// Takes, a buffer at a time, at most `batches` buffers (unlimited: 0): `take`
// fills the buffer and returns how many samples it holds, `fn` handles the
// i-th. True when samples may remain: taking resets DATA_AVAILABLE while
// samples may remain, so a full buffer is followed by another take, here or
// on the next call.
template <class Take, class Fn>
bool take_batches(Take take, std::size_t capacity, std::size_t batches, Logger& log,
                  const char* what, Fn fn) {
  for (std::size_t n = 0; batches == 0 || n < batches; ++n) {
    auto taken = take();
    if (!taken) {
      log.error("taking {} failed: {}", what, taken.error().message());
      return false;
    }
    for (std::size_t i = 0; i < *taken; ++i) fn(i);
    if (*taken < capacity) return false;
  }
  return true;
}

// Takes every sample waiting (a take resets DATA_AVAILABLE: what a full
// take leaves would wait for the next sample) and hands each to `fn`.
template <class T, class Fn>
void take_all(dds::Reader<T>& reader, Logger& log, const char* what, Fn fn) {
  for (;;) {
    auto taken = reader.take(kBatch);
    if (!taken) {
      log.error("taking {} failed: {}", what, taken.error().message());
      return;
    }
    for (const auto& sample : *taken) fn(sample);
    if (taken->size() < kBatch) return;
  }
}

}  // namespace

void HandoffLogSink::write_structured(LogLevel level, std::string_view component,
                                      std::string_view message, std::span<const LogField> fields) {
  {
    std::lock_guard lock(mutex_);
    if (lines_.size() >= kCapacity) {
      ++dropped_;
      return;
    }
    Line line{level, std::string(component), std::string(message), {}};
    for (const auto& f : fields) line.fields.emplace_back(f.name, f.value);
    lines_.push_back(std::move(line));
  }
  ready_();
}

std::size_t HandoffLogSink::drain() {
  std::vector<Line> lines;
  std::size_t dropped = 0;
  {
    std::lock_guard lock(mutex_);
    lines.swap(lines_);
    std::swap(dropped, dropped_);
  }
  for (const auto& l : lines) {
    std::vector<LogField> fields;
    for (const auto& [name, value] : l.fields) fields.push_back({name, value});
    target_.write_structured(l.level, l.component, l.message, fields);
  }
  return dropped;
}

thread_local bool DrainFirstLogSink::in_before_ = false;

void DrainFirstLogSink::write_structured(LogLevel level, std::string_view component,
                                         std::string_view message,
                                         std::span<const LogField> fields) {
  if (!in_before_) {
    in_before_ = true;
    struct Reset {
      ~Reset() { in_before_ = false; }
    } reset;
    before_();
  }
  target_.write_structured(level, component, message, fields);
}

DdsInput::DdsInput(const dds::Participant& participant, DdsPublisher& publisher, std::string rack,
                   std::map<std::string, port::PortLoop*, std::less<>> ports, Logger log,
                   std::function<void(ReloadCall)> reload, Duration max_commander_lease,
                   std::span<const ProfileTopics> profiles)
    : rack_(std::move(rack)),
      publisher_(publisher),
      ports_(std::move(ports)),
      log_(std::move(log)),
      partition_{dds::rack_partition(rack_)},
      commands_held_(participant),
      participant_(participant),
      max_commander_lease_(max_commander_lease),
      command_listener_([this] { on_commands_available(); }),
      requests_(participant, publisher.request_topic(), dds::request_reader_qos(partition_)),
      reload_(std::move(reload)),
      request_buffer_(kBatch),
      stop_(participant),
      waitset_(participant),
      log_waiting_(participant),
      silenced_(participant),
      command_sink_(log_.sink(), [this] { (void)log_waiting_.trigger(); }),
      command_log_(log_.to(command_sink_)),
      own_sink_(log_.sink(), [this] { drain_command_log(); }) {
  log_ = log_.to(own_sink_);
  for (const ProfileTopics& profile : profiles) {
    const auto make = [&] { return profile.make_command(participant); };
    if (profile.required) {
      command_topics_.push_back(make());
    } else if (auto topic = unless_denied(log_,
                                          fmt::format("the commands of profile \"{}\" ({})",
                                                      profile.profile, profile.command_topic),
                                          make)) {
      command_topics_.push_back(std::move(*topic));
    }
  }
  {
    std::lock_guard lock(command_take_mutex_);
    ensure_command_classes();
    if (command_classes_.empty() || command_classes_.front()->refresh_ms != 0) {
      throw std::runtime_error("creating the readers of the commands failed (logged)");
    }
  }
  // Readers of the services that DDS Security grants (the publisher has
  // their topics), each as far as it grants it.
  if (const auto* topic = publisher.scan_request_topic()) {
    scan_requests_ = unless_denied(log_, "the bus scan's requests (dnbridge/BusScanRequest)", [&] {
      return dds::Reader<dnbridge_BusScanRequest>(participant, *topic,
                                                  dds::request_reader_qos(partition_));
    });
  }
  if (const auto* topic = publisher.reload_request_topic()) {
    reload_requests_ = unless_denied(log_, "reload requests (dnbridge/ReloadRequest)", [&] {
      return dds::Reader<dnbridge_ReloadRequest>(participant, *topic,
                                                 dds::request_reader_qos(partition_));
    });
  }
  // A reader's status condition stays triggered while any status in its mask
  // is set, and taking resets only DATA_AVAILABLE: with the default mask
  // (every status) a matched writer's SUBSCRIPTION_MATCHED, never read here,
  // would keep the waitset triggered and this thread spinning.
  std::vector<const dds::Entity*> readers{&requests_};
  if (scan_requests_) readers.push_back(&*scan_requests_);
  if (reload_requests_) readers.push_back(&*reload_requests_);
  for (const dds::Entity* reader : readers) {
    if (!reader->set_status_mask(DDS_DATA_AVAILABLE_STATUS)) {
      throw std::runtime_error("setting the status mask of a DDS input reader failed");
    }
  }
  waitset_.attach(commands_held_, kCommandsHeld);
  waitset_.attach(requests_, kRequests);
  if (scan_requests_) waitset_.attach(*scan_requests_, kScanRequests);
  if (reload_requests_) waitset_.attach(*reload_requests_, kReloadRequests);
  waitset_.attach(stop_, kStop);
  waitset_.attach(log_waiting_, kLogWaiting);
  waitset_.attach(silenced_, kSilenced);
  for (const auto& [name, loop] : ports_) {
    auto& seen = silences_seen_[name];
    for (unsigned m = 0; m <= devicenet::MacId::kMax; ++m) {
      seen[m] = loop->silences(*devicenet::MacId::from(m));
    }
    loop->watch_command_state([this] { (void)silenced_.trigger(); });
  }
}

DdsInput::~DdsInput() { stop(); }

void DdsInput::start() {
  thread_ = std::thread([this] { run(); });
  port::name_thread(thread_, "dds input");
  accepting_ = true;
  commands_pending_ = true;  // any that came before
  deliver_commands();
}

void DdsInput::stop() {
  accepting_ = false;
  for (const auto& [name, loop] : ports_) loop->watch_command_state({});
  // No listener call after this: none is handing a command to a port.
  {
    std::lock_guard lock(command_take_mutex_);
    classes_closed_ = true;
    const auto detach = [](const CommandClass& c) {
      for (const auto& r : c.readers) (void)dds::DataListener::detach(r->entity());
    };
    for (const auto& c : command_classes_) detach(*c);
    for (const auto& [key, c] : node_readers_) detach(*c);
  }
  if (!thread_.joinable()) return;
  (void)stop_.trigger();
  thread_.join();
  drain_command_log();
}

void DdsInput::drain_command_log() {
  if (const auto dropped = command_sink_.drain(); dropped > 0) {
    // Straight to the target: through log_, newer handed-off lines would
    // be drained before this one.
    log_.to(own_sink_.target())
        .warn("{} more lines of the command path not logged (more than {} waited)", dropped,
              HandoffLogSink::kCapacity);
  }
}

port::PortLoop* DdsInput::port_of(std::string_view name) {
  auto it = ports_.find(name);
  return it == ports_.end() ? nullptr : it->second;
}

void DdsInput::run() {
  // Requests in batches, and commands held off by a flood at the end of
  // the hold-off (deliver_commands).
  bool requests_left = false;
  bool commands_held = false;
  for (;;) {
    Duration timeout = requests_left ? Duration::zero() : seconds(1);
    const TimePoint held_until{Duration(next_command_take_.load())};
    if (commands_held) {
      timeout = std::min(timeout, std::max(Duration::zero(), held_until - port::steady_now()));
    }
    auto triggered = waitset_.wait(timeout);
    if (!triggered) {
      log_.error("waiting for DDS input failed: {}", triggered.error().message());
      continue;
    }
    bool requests = requests_left;
    for (auto token : *triggered) {
      if (token == kStop) return;
      if (token == kCommandsHeld) {
        (void)commands_held_.take_triggered();
        commands_held = true;
      }
      requests = requests || token == kRequests;
      if (token == kScanRequests) take_scan_requests();
      if (token == kReloadRequests) take_reload_requests();
      if (token == kLogWaiting) {
        (void)log_waiting_.take_triggered();
        drain_command_log();
      }
      if (token == kSilenced) {
        (void)silenced_.take_triggered();
        {
          std::lock_guard lock(command_take_mutex_);
          make_readers_of_silenced_nodes();
        }
        commands_pending_ = true;  // any that came while the new readers were made
        deliver_commands();
      }
    }
    if (commands_held && port::steady_now() >= TimePoint{Duration(next_command_take_.load())}) {
      commands_held = false;
      held_signalled_ = false;
      commands_pending_ = true;
      deliver_commands();
    }
    requests_left = requests && take_requests();
    if (refresh_generations() != classes_for_generation_) {
      {
        std::lock_guard lock(command_take_mutex_);
        ensure_command_classes();
      }
      commands_pending_ = true;  // any that came while the new readers were made
      deliver_commands();
    }
  }
}

std::uint64_t DdsInput::refresh_generations() const {
  std::uint64_t sum = 0;
  for (const auto& [name, loop] : ports_) sum += loop->refresh_generation();
  return sum;
}

void DdsInput::ensure_command_classes() {
  classes_for_generation_ = refresh_generations();
  drop_stale_node_readers();
  ensure_command_class(0);
  for (const auto& [name, loop] : ports_) {
    for (unsigned m = 0; m <= devicenet::MacId::kMax; ++m) {
      const std::uint32_t ms = loop->command_refresh_ms(*devicenet::MacId::from(m));
      if (ms != 0) ensure_command_class(ms);
    }
  }
}

void DdsInput::prepare_command_refreshes(const std::vector<std::uint32_t>& refreshes) {
  {
    std::lock_guard lock(command_take_mutex_);
    for (const std::uint32_t ms : refreshes) ensure_command_class(ms);
  }
  commands_pending_ = true;  // any that came while the new readers were made
  deliver_commands();
}

void DdsInput::ensure_command_class(std::uint32_t ms) {
  if (classes_closed_) return;
  if (std::any_of(command_classes_.begin(), command_classes_.end(),
                  [&](const auto& c) { return c->refresh_ms == ms; })) {
    return;
  }
  const auto deadline = ms == 0 ? std::nullopt : std::optional<Duration>(milliseconds(ms));
  const dds::Qos qos = dds::command_reader_qos(partition_, max_commander_lease_, deadline);
  try {
    auto made = std::make_unique<CommandClass>();
    made->refresh_ms = ms;
    for (const auto& topic : command_topics_) {
      const auto make = [&] {
        return topic->reader(participant_, qos, command_listener_.get(), nullptr);
      };
      if (topic->required()) {
        made->readers.push_back(make());
      } else if (auto r =
                     unless_denied(log_, fmt::format("the commands of {}", topic->name()), make)) {
        made->readers.push_back(std::move(*r));
      }
    }
    if (ms != 0) {
      log_.info(
          "commands of the nodes with command_refresh_ms = {} are taken from writers offering a "
          "deadline of at most {} ms",
          ms, ms);
    }
    command_classes_.push_back(std::move(made));
  } catch (const std::exception& e) {
    // Their commands are not taken: a command in force lapses at its refresh.
    log_.error("no command reader for the nodes with command_refresh_ms = {}: {}", ms, e.what());
  }
}

void DdsInput::make_readers_of_silenced_nodes() {
  for (const auto& [name, loop] : ports_) {
    auto& seen = silences_seen_[name];
    for (unsigned m = 0; m <= devicenet::MacId::kMax; ++m) {
      const auto mac = *devicenet::MacId::from(m);
      const std::uint32_t silences = loop->silences(mac);
      if (silences == seen[m]) continue;
      seen[m] = silences;
      const std::uint32_t refresh = loop->command_refresh_ms(mac);
      if (!loop->has_node(mac) || refresh == 0) continue;  // a reload came since
      make_node_readers(name, mac, loop->profile_of(mac), refresh);
    }
  }
}

void DdsInput::make_node_readers(const std::string& port, devicenet::MacId mac,
                                 std::string_view profile, std::uint32_t refresh_ms) {
  if (classes_closed_) return;
  // The previous one goes first: the silent owner of the node is its.
  if (auto it = node_readers_.find(NodeRef{port, mac.value()}); it != node_readers_.end()) {
    node_readers_.erase(it);
  }
  const auto topic = std::find_if(command_topics_.begin(), command_topics_.end(),
                                  [&](const auto& t) { return t->profile() == profile; });
  if (topic == command_topics_.end()) return;  // DDS Security grants no command of the profile
  const dds::Qos qos =
      dds::command_reader_qos(partition_, max_commander_lease_, milliseconds(refresh_ms));
  try {
    auto key = std::make_unique<NodeKey>(NodeKey{rack_, port, mac.value()});
    auto made = std::make_unique<CommandClass>();
    made->refresh_ms = refresh_ms;
    made->profile = (*topic)->profile();
    made->readers.push_back(
        (*topic)->reader(participant_, qos, command_listener_.get(), key.get()));
    made->node = std::move(key);
    const NodeKey& k = *made->node;
    command_log_.debug(
        "port {} node {}: its commander went silent; its commands are taken by a reader of its "
        "own, made afresh, so that the next live commander by strength takes it over",
        port, mac.value());
    node_readers_.emplace(k, std::move(made));
  } catch (const std::exception& e) {
    // The node's class takes its commands: a weaker commander does not take
    // over from the silent one.
    command_log_.error("port {} node {}: no command reader of its own: {}", port, mac.value(),
                       e.what());
  }
}

void DdsInput::drop_stale_node_readers() {
  for (auto it = node_readers_.begin(); it != node_readers_.end();) {
    const NodeKey& k = it->first;
    port::PortLoop* loop = port_of(k.port);
    const auto mac = *devicenet::MacId::from(k.mac);
    const bool same = loop && loop->profile_of(mac) == it->second->profile &&
                      loop->command_refresh_ms(mac) == it->second->refresh_ms;
    it = same ? std::next(it) : node_readers_.erase(it);
  }
}

void DdsInput::on_commands_available() {
  commands_pending_ = true;
  deliver_commands();
}

void DdsInput::deliver_commands() {
  do {
    std::unique_lock lock(command_take_mutex_, std::try_to_lock);
    if (!lock) return;  // its holder looks at commands_pending_ again after
    while (accepting_ && commands_pending_.exchange(false)) {
      const TimePoint now = port::steady_now();
      if (now < TimePoint{Duration(next_command_take_.load())}) {
        // Held off: the samples stay in the reader (keep-last 1 per node:
        // the newest of each is taken at the end of the hold-off, by the
        // input thread), and meanwhile a sample costs this check only.
        commands_pending_ = true;
        if (!held_signalled_.exchange(true)) {
          ++command_holdoffs_;
          (void)commands_held_.trigger();
        }
        break;  // to the look after unlocking: the hold-off may have ended meanwhile
      }
      take_commands();
      next_command_take_ = (now + kCommandHoldoff).time_since_epoch().count();
    }
    // A thread that found the lock taken left its commands to this one.
  } while (accepting_ && commands_pending_ && !held_signalled_);
}

void DdsInput::take_commands() {
  for (const auto& cls : command_classes_) {
    take_commands(*cls);
  }
  for (const auto& [key, cls] : node_readers_) take_commands(*cls);
}

void DdsInput::take_commands(const CommandClass& from) {
  for (const auto& reader : from.readers) {
    reader->take(command_log_, [&](const CommandSample& c) { on_command(c, from); });
  }
}

port::PortLoop* DdsInput::loop_for(const CommandSample& c, const CommandClass& from) {
  port::PortLoop* loop = port_of(c.port);
  const auto mac = devicenet::MacId::from(c.mac);
  const std::string_view profile = loop && mac ? loop->profile_of(*mac) : std::string_view{};
  // Every class's readers have every instance: a node's commands are its
  // own readers' when it has them, else its class's, and a refusal is said
  // once, by the class without refresh.
  if (profile == c.profile && !profile.empty()) {
    const std::uint32_t refresh = loop->command_refresh_ms(*mac);
    if (refresh != from.refresh_ms) return nullptr;
    if (from.node) {
      return from.node->port == loop->name() && from.node->mac == mac->value() ? loop : nullptr;
    }
    // The node's own reader, while it is of the node's refresh and profile
    // (a reload may have changed either: then its class takes them).
    const auto own = node_readers_.find(NodeRef{loop->name(), mac->value()});
    const bool taken_by_own = own != node_readers_.end() && own->second->refresh_ms == refresh &&
                              own->second->profile == profile;
    return taken_by_own ? nullptr : loop;
  }
  if (from.refresh_ms != 0 || from.node) return nullptr;
  command_warn_limit_.warn(
      command_log_, port::steady_now(), "{} sample{} for port \"{}\" MAC {} refused: {}", c.topic,
      c.info.valid_data() ? fmt::format(" from {}", c.issuer) : "", c.port, c.mac,
      profile.empty() ? std::string("not in this rack's configuration")
                      : fmt::format("the node's profile is \"{}\"; {} commands the nodes of "
                                    "profile \"{}\"",
                                    profile, c.topic, c.profile));
  return nullptr;
}

void DdsInput::on_command(const CommandSample& c, const CommandClass& from) {
  if (c.rack != rack_) return;  // another bridge's node
  const dds::SampleInfo& info = c.info;
  port::PortLoop* loop = loop_for(c, from);
  if (!loop) return;
  if (info.valid_data()) commands_taken_.fetch_add(1, std::memory_order_relaxed);
  const auto mac = devicenet::MacId::from(c.mac);
  // No live commander left for this node (all writers gone, or disposed):
  // idle. A command taken after its writer left carries that state itself,
  // with no sample of its own to tell it; it is not applied: a commander
  // that is gone commands nothing, not even for a moment.
  if (info.instance_state() != dds::InstanceState::kAlive) {
    loop->release_command(*mac);
    return;
  }
  if (!info.valid_data()) return;
  note_clock_skew(c);
  loop->command(*mac, c.outputs(), std::string(c.issuer));
}

void DdsInput::note_clock_skew(const CommandSample& c) {
  const dds::SampleInfo& info = c.info;
  // Commands are applied in the order they arrive, whatever their stamps
  // (dds::command_reader_qos): a commander's clock cannot hold a pump. A
  // stamp far ahead still says that a commander's clock is wrong, and other
  // readers of its samples (ordered by source timestamp) will be misled.
  const auto ahead = info.source_timestamp() - dds::dds_now();
  if (ahead <= kClockSkewReported) return;
  ++commands_stamped_ahead_;
  skew_limit_.warn(
      command_log_, port::steady_now(),
      "command from \"{}\" for port \"{}\" MAC {} is stamped {:.1f} s ahead of this host's "
      "clock ({} such commands so far): applied in the order received; check the commander's "
      "clock synchronisation",
      c.issuer, c.port, c.mac, std::chrono::duration<double>(ahead).count(),
      commands_stamped_ahead_);
}

bool DdsInput::take_requests() {
  // Serialized as well: a requester name is checked whole (see on_request).
  return take_batches([this] { return requests_.take(request_buffer_, request_cdr_); },
                      request_buffer_.capacity(), kRequestBatches, log_, "explicit requests",
                      [this](std::size_t i) {
                        if (request_buffer_.info(i).valid_data())
                          on_request(request_buffer_.data(i), request_cdr_[i]);
                      });
}

void DdsInput::take_scan_requests() {
  // Each asks for at most one scan of a port: every one waiting, taken now.
  take_all(*scan_requests_, log_, "bus scan requests",
           [this](const auto& sample) { on_scan_request(sample); });
}

void DdsInput::on_scan_request(const dds::Sample<dnbridge_BusScanRequest>& sample) {
  if (!sample.valid_data()) return;  // a requester unregistered its request
  const auto& r = sample.data();
  if (dds::view(r.rack) != rack_) return;
  port::ScanCall call{std::string(dds::view(r.requester)), r.txid};
  const std::string_view port = dds::view(r.port);
  // A reply carries the requester name and may quote the port's.
  if (call.requester.size() + port.size() > kMaxRequestBytes) {
    warn_limit_.warn(log_, port::steady_now(),
                     "bus scan request (txid {}) dropped unanswered: names of {} bytes, at "
                     "most {} served",
                     call.txid, call.requester.size() + port.size(), kMaxRequestBytes);
    return;
  }
  if (port::PortLoop* loop = port_of(port)) {
    loop->scan_request(std::move(call));
    return;
  }
  publisher_.bus_scan_reply(std::string(port),
                            port::refuse(call, rack::TransactionStatus::kInvalidPort,
                                         fmt::format("rack {} has no port \"{}\"", rack_, port)));
}

void DdsInput::take_reload_requests() {
  take_all(*reload_requests_, log_, "reload requests",
           [this](const dds::Sample<dnbridge_ReloadRequest>& sample) {
             if (!sample.valid_data()) return;
             const auto& r = sample.data();
             if (dds::view(r.rack) != rack_) return;
             ReloadCall call{std::string(dds::view(r.requester)), r.txid};
             if (call.requester.empty() || call.requester.size() > kMaxRequestBytes) {
               // No name to answer to, or one too long to carry back.
               warn_limit_.warn(log_, port::steady_now(),
                                "reload request (txid {}) dropped unanswered: a requester name of "
                                "{} bytes (1 to {} served)",
                                call.txid, call.requester.size(), kMaxRequestBytes);
               return;
             }
             if (reload_) reload_(std::move(call));
           });
}

void DdsInput::on_request(const dnbridge_ExplicitRequest& r,
                          std::span<const unsigned char> serialized) {
  if (dds::view(r.rack) != rack_) return;
  requests_taken_.fetch_add(1, std::memory_order_relaxed);
  if (serialized.size() > kMaxRequestBytes) {
    // Not answered: the reply would carry the oversized name back.
    ++requests_dropped_for_size_;
    constexpr std::size_t kQuoted = 64;
    const std::string_view requester = dds::view(r.requester);
    warn_limit_.warn(log_, port::steady_now(),
                     "explicit request (txid {}) from \"{}{}\" dropped unanswered: {} bytes "
                     "serialized, at most {} served ({} such requests so far)",
                     r.txid, requester.substr(0, kQuoted), requester.size() > kQuoted ? "..." : "",
                     serialized.size(), kMaxRequestBytes, requests_dropped_for_size_);
    return;
  }
  rack::ExplicitCall call = call_of(r);
  if (dds::leading_string_has_nul(serialized)) {
    // The name reads as its part before the NUL: two such requesters would
    // take each other's transactions. Not executed; the reply goes to the
    // part before the NUL (a C string cannot say more).
    ++requests_refused_for_names_;
    warn_limit_.warn(log_, port::steady_now(),
                     "explicit request (txid {}) refused: its requester name \"{}\" goes on past "
                     "a NUL character ({} such requests so far)",
                     call.txid, call.requester, requests_refused_for_names_);
    publisher_.explicit_reply(
        {}, rack::refuse(call, rack::TransactionStatus::kInvalidCommand,
                         "the requester name holds a NUL character: use a name without one"));
    return;
  }
  port::PortLoop* loop = port_of(call.port);
  if (!loop) {
    publisher_.explicit_reply(
        {}, rack::refuse(call, rack::TransactionStatus::kInvalidPort,
                         fmt::format("rack {} has no port \"{}\"", rack_, call.port)));
    return;
  }
  loop->explicit_request(std::move(call));
}

}  // namespace dnbridge::daemon
