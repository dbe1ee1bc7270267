#pragma once
// A simulated CDN127: a Group 2 only DeviceNet slave of the predefined
// master/slave connection set (explicit + poll), in front of a dry pump.
//
// Sans-IO: frames come in through on_frame(), time through on_timer() (call
// it when now >= next_deadline()), frames go out through the FrameSink given
// at construction. No threads, no clocks.
//
// Wire behaviour (devicenet-facts §1..§5, CDN127 manual "DeviceNet Message
// Types"): it listens to Group 2 messages 4 (explicit request), 5 (poll
// command), 6 (Allocate/Release) and 7 (duplicate MAC check) for its MAC, and
// answers on Group 2 message 3 (explicit and unconnected responses), Group 1
// message 15 (poll response) and Group 2 message 7. Everything else (UCMM,
// Group 1/3, bit strobe, the Group 4 offline set) is ignored and counted.
#include <cstdint>

#include "adapters/sim/cdn127_device.hpp"
#include "adapters/sim/cdn127_objects.hpp"
#include "adapters/sim/pump_model.hpp"
#include "bridge/can/frame_sink.hpp"
#include "bridge/common/log.hpp"
#include "bridge/devicenet/duplicate_mac.hpp"
#include "bridge/devicenet/fragmentation.hpp"

namespace dnbridge::sim {

struct SlaveCounters {
  std::uint32_t frames_not_addressed = 0;  // other nodes' traffic
  std::uint32_t frames_ignored = 0;        // for us but dropped (unsupported, wrong state, malformed)
  std::uint32_t requests_refused = 0;      // answered with an error response
  std::uint32_t explicit_requests = 0;     // explicit requests executed (success or error)
  std::uint32_t polls_applied = 0;
  std::uint32_t polls_idle = 0;
  std::uint32_t polls_oversize = 0;        // longer than the consumed size: ignored
  std::uint32_t polls_invalid = 0;
  std::uint32_t polls_ignored = 0;         // no established poll connection
  std::uint32_t fragment_transfers_failed = 0;
  std::uint32_t restarts = 0;              // power-ups, Identity Reset, MAC change
};

class Cdn127Slave {
 public:
  enum class NetworkState : std::uint8_t {
    kOff,                  // before power_on()
    kDuplicateMacCheck,    // silent except for the check
    kOnline,
    kCommunicationFault,   // duplicate MAC detected: silent until power cycled
  };

  Cdn127Slave(can::FrameSink& sink, SlaveOptions options = {}, Logger log = {});

  // First power-up (and power_cycle() for later ones): volatile state reset,
  // switches read, outputs off, the duplicate MAC check started. E2 persists.
  void power_on(TimePoint now) noexcept;
  void power_cycle(TimePoint now) noexcept { power_on(now); }

  void on_frame(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_timer(TimePoint now) noexcept;
  TimePoint next_deadline() const noexcept;

  // --- observation and the test's hands on the device ---
  NetworkState network_state() const noexcept { return network_; }
  devicenet::MacId mac() const noexcept { return device_.mac(); }
  // 255 when no master owns the connection set.
  std::uint8_t owner() const noexcept { return device_.owner(); }
  ConnectionState explicit_state() const noexcept { return device_.explicit_connection().state; }
  ConnectionState poll_state() const noexcept { return device_.poll_connection().state; }
  const profiles::cdn127::PumpOutputs& outputs() const noexcept { return device_.pump().outputs(); }
  const SlaveCounters& counters() const noexcept { return counters_; }
  PumpModel& pump() noexcept { return device_.pump(); }
  const PumpModel& pump() const noexcept { return device_.pump(); }
  Cdn127Device& device() noexcept { return device_; }
  const Cdn127Device& device() const noexcept { return device_; }
  // Turns the front-panel switches; read at the next power-up.
  void set_switches(std::uint8_t mac_switch, std::uint8_t baud_switch) noexcept {
    device_.set_switches(mac_switch, baud_switch);
  }

 private:
  void send(std::uint32_t id, Bytes payload, TimePoint now) noexcept;
  void on_duplicate_mac(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_unconnected(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_explicit(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_poll(const can::CanFrame& frame, TimePoint now) noexcept;
  void handle_explicit_message(std::uint8_t header, Bytes message, TimePoint now) noexcept;
  void send_explicit_response(std::uint8_t header, Bytes message, TimePoint now) noexcept;
  void after_response(TimePoint now) noexcept;
  void restart(TimePoint now) noexcept;
  void enter_communication_fault() noexcept;
  std::uint32_t response_id() const noexcept;

  can::FrameSink& sink_;
  Logger log_;
  Cdn127Device device_;
  devicenet::DuplicateMacCheck dup_check_;
  devicenet::ExplicitReassembler reassembler_;
  devicenet::ExplicitFragmentSender sender_;
  NetworkState network_ = NetworkState::kOff;
  SlaveCounters counters_;
};

const char* to_string(Cdn127Slave::NetworkState s) noexcept;

}  // namespace dnbridge::sim
