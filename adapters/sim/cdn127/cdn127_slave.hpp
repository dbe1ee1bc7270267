#pragma once
// A simulated CDN127: a Group 2 only DeviceNet slave of the predefined
// master/slave connection set (explicit + poll), in front of a dry pump.
//
// Sans-IO: frames come in through on_frame(), time through on_timer() (call
// it when now >= next_deadline()), frames go out through the FrameSink given
// at construction. No threads, no clocks.
//
// Wire behaviour (bridge/PROTOCOL.md §1..§7, CDN127 manual "DeviceNet Message
// Types"): it listens to Group 2 messages 4 (explicit request), 5 (poll
// command), 6 (Allocate/Release) and 7 (duplicate MAC check) for its MAC, and
// answers on Group 2 message 3 (explicit and unconnected responses), Group 1
// message 15 (poll response) and Group 2 message 7. Everything else (UCMM,
// Group 1/3, bit strobe) is ignored and counted.
//
// The wire (duplicate MAC check, explicit messaging and its fragments,
// Allocate/Release on the unconnected port, poll, the Group 4 Offline
// Connection Set in Communication Fault, delayed responses) is Group2Slave's
// (adapters/sim/generic/group2_slave.hpp), with the CDN127's readings of it
// in SlaveOptions; this class is the CDN127 behind it.
#include <cstddef>
#include <cstdint>

#include "adapters/sim/cdn127/cdn127_device.hpp"
#include "adapters/sim/cdn127/cdn127_objects.hpp"
#include "adapters/sim/cdn127/pump_model.hpp"
#include "adapters/sim/generic/group2_slave.hpp"
#include "bridge/can/frame_sink.hpp"
#include "bridge/common/log.hpp"

namespace dnbridge::sim {

class Cdn127Slave final : public Group2Slave {
 public:
  Cdn127Slave(can::FrameSink& sink, SlaveOptions options = {}, Logger log = {});

  // power_on(): first power-up (and power_cycle() for later ones): volatile
  // state reset, switches read, outputs off, the duplicate MAC check started.
  // E2 persists. Unrecoverable Identity faults end, recoverable ones stay
  // (IdentityFaults); a restart (Identity Reset, a new MAC) keeps both.

  // --- observation and the test's hands on the device ---
  devicenet::MacId mac() const noexcept { return device_.mac(); }
  // 255 when no master owns the connection set.
  std::uint8_t owner() const noexcept { return device_.owner(); }
  ConnectionState explicit_state() const noexcept { return device_.explicit_connection().state; }
  ConnectionState poll_state() const noexcept { return device_.poll_connection().state; }
  const profiles::cdn127::PumpOutputs& outputs() const noexcept { return device_.pump().outputs(); }
  PumpModel& pump() noexcept { return device_.pump(); }
  const PumpModel& pump() const noexcept { return device_.pump(); }
  Cdn127Device& device() noexcept { return device_; }
  const Cdn127Device& device() const noexcept { return device_; }
  // Turns the front-panel switches; read at the next power-up.
  void set_switches(std::uint8_t mac_switch, std::uint8_t baud_switch) noexcept {
    device_.set_switches(mac_switch, baud_switch);
  }

 private:
  devicenet::MacId device_mac() const noexcept override { return device_.mac(); }
  const ConnectionSet& connection_set() const noexcept override { return device_.connections(); }
  ConnectionSet& connection_set() noexcept override { return device_.connections(); }
  void power_up_device(TimePoint now, PowerUpCause cause) noexcept override {
    device_.power_up(now, cause);
  }
  void advance_device(TimePoint now) noexcept override { device_.pump().advance(now); }
  TimePoint process_deadline() const noexcept override { return device_.pump().next_deadline(); }
  void device_timer(TimePoint now) noexcept override { device_.on_timer(now); }
  TimePoint device_deadline() const noexcept override { return device_.next_deadline(); }
  std::size_t execute(const devicenet::RequestMessage& request, std::uint8_t requester,
                      TimePoint now, MutableBytes out) noexcept override {
    return execute_request(device_, request, requester, now, out);
  }
  PendingAction take_pending_action() noexcept override { return device_.take_pending_action(); }
  void restore_factory_defaults() noexcept override { device_.restore_factory_defaults(); }
  PollResult poll(Bytes command, TimePoint now) noexcept override {
    return device_.on_poll(command, now);
  }
  void go_offline(TimePoint now) noexcept override { device_.go_offline(now); }
  Reply set_mac(std::uint8_t mac) noexcept override { return device_.set_mac(mac); }

  Cdn127Device device_;
};

}  // namespace dnbridge::sim
