#include "adapters/daemon/dds_publisher.hpp"

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

DdsPublisher::DdsPublisher(const dds::Participant& participant, std::string rack,
                           Duration state_deadline, Logger log)
    : rack_(std::move(rack)),
      log_(std::move(log)),
      partition_{dds::rack_partition(rack_)},
      pump_topic_(participant),
      node_topic_(participant),
      port_topic_(participant),
      command_topic_(participant),
      request_topic_(participant),
      reply_topic_(participant),
      pump_writer_(participant, pump_topic_, dds::state_writer_qos(state_deadline)),
      node_writer_(participant, node_topic_, dds::state_writer_qos(state_deadline)),
      port_writer_(participant, port_topic_, dds::state_writer_qos(state_deadline)),
      reply_writer_(participant, reply_topic_, dds::reply_writer_qos(partition_)),
      devices_(unless_denied(
          log_, "the devices' state (dnbridge/DeviceState)",
          [&] { return DeviceOut(participant, dds::state_writer_qos(state_deadline)); })),
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
      reply_out_("dds reply out", kReplyBacklog) {}

void DdsPublisher::check_state(Status s, const char* what) {
  if (!check(s, what)) state_write_failures_.fetch_add(1, std::memory_order_relaxed);
}

bool DdsPublisher::check(Status s, const char* what) {
  if (s) return true;
  std::lock_guard lock(log_mutex_);
  error_limit_.error(log_, port::steady_now(), "writing {} failed: {}", what, s.error().message());
  return false;
}

namespace {

// A node's instance of a state topic.
template <class T>
dds::Owned<T> key_of(const std::string& rack, const std::string& port, std::uint8_t mac) {
  dds::Owned<T> key;
  dds::set_string(key->rack, rack);
  dds::set_string(key->port, port);
  key->mac = mac;
  return key;
}

}  // namespace

void DdsPublisher::note_written(const std::string& port, std::uint8_t mac, Written kind) {
  std::lock_guard lock(mutex_);
  written_[port][mac] = kind;
}

void DdsPublisher::pump_state(const std::string& port, const rack::PumpView& pump,
                              TimePoint source_time) {
  note_written(port, pump.mac.value(), Written::kPump);
  dds::Owned<dnbridge_PumpState> sample;
  fill_pump_state(*sample, rack_, port, pump);
  check_state(pump_writer_.write(*sample, clock_.to_wall(source_time)), "PumpState");
}

void DdsPublisher::node_status(const std::string& port, const rack::PumpView& pump,
                               const port::NodeStatusView& node, TimePoint source_time) {
  dds::Owned<dnbridge_NodeStatus> sample;
  fill_node_status(*sample, rack_, port, pump, node);
  check_state(node_writer_.write(*sample, clock_.to_wall(source_time)), "NodeStatus");
}

void DdsPublisher::device_state(const std::string& port, const rack::DeviceView& device,
                                TimePoint source_time) {
  if (!devices_) return;
  note_written(port, device.mac.value(), Written::kDevice);
  dds::Owned<dnbridge_DeviceState> sample;
  fill_device_state(*sample, rack_, port, device);
  check_state(devices_->writer.write(*sample, clock_.to_wall(source_time)), "DeviceState");
}

void DdsPublisher::device_status(const std::string& port, const rack::DeviceView& device,
                                 const port::NodeStatusView& node, TimePoint source_time) {
  note_written(port, device.mac.value(), Written::kDevice);
  dds::Owned<dnbridge_NodeStatus> sample;
  fill_node_status(*sample, rack_, port, device, node);
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

void DdsPublisher::release_node(const std::string& port, std::uint8_t mac, Written kind,
                                bool dispose) {
  const auto now = dds::dds_now();
  const auto node_key = key_of<dnbridge_NodeStatus>(rack_, port, mac);
  if (kind == Written::kPump) {
    const auto key = key_of<dnbridge_PumpState>(rack_, port, mac);
    if (dispose) check_state(pump_writer_.dispose(*key, now), "PumpState disposal");
    check_state(pump_writer_.unregister_instance(*key, now), "PumpState unregistration");
  } else if (devices_) {
    const auto key = key_of<dnbridge_DeviceState>(rack_, port, mac);
    if (dispose) check_state(devices_->writer.dispose(*key, now), "DeviceState disposal");
    check_state(devices_->writer.unregister_instance(*key, now), "DeviceState unregistration");
  }
  if (dispose) check_state(node_writer_.dispose(*node_key, now), "NodeStatus disposal");
  check_state(node_writer_.unregister_instance(*node_key, now), "NodeStatus unregistration");
}

void DdsPublisher::node_removed(const std::string& port, devicenet::MacId mac) {
  std::optional<Written> kind;
  {
    std::lock_guard lock(mutex_);
    auto& macs = written_[port];
    if (auto it = macs.find(mac.value()); it != macs.end()) {
      kind = it->second;
      macs.erase(it);
    }
  }
  // Disposed: the node is no longer the rack's (or no longer of that
  // profile), which unregistering (the bridge gone) would not say. Only
  // what was written.
  if (kind) release_node(port, mac.value(), *kind, true);
}

void DdsPublisher::port_stopped(const std::string& port) {
  // Unregister, never dispose: the last samples (online false, stopped) stay
  // what late readers see until the bridge is back.
  std::map<std::uint8_t, Written> macs;
  {
    std::lock_guard lock(mutex_);
    macs = std::move(written_[port]);
    written_.erase(port);
  }
  for (const auto& [mac, kind] : macs) release_node(port, mac, kind, false);
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
  (void)pump_writer_.wait_for_acks(left());
  (void)node_writer_.wait_for_acks(left());
  (void)port_writer_.wait_for_acks(left());
  (void)reply_writer_.wait_for_acks(left());
  if (scan_) (void)scan_->writer.wait_for_acks(left());
  if (reload_) (void)reload_->writer.wait_for_acks(left());
}

}  // namespace dnbridge::daemon
