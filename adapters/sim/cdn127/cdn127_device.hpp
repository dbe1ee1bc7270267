#pragma once
// The state of a simulated CDN127 and the rules that change it: allocation,
// the two predefined connections and their watchdogs, the E2 (non-volatile)
// settings, outputs with their fault and idle actions, and poll processing.
// No frames here: cdn127_slave.hpp moves bytes, cdn127_objects.hpp maps
// attributes onto this state.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "adapters/sim/cdn127/pump_model.hpp"
#include "adapters/sim/generic/connection_object.hpp"
#include "adapters/sim/generic/connection_set.hpp"
#include "adapters/sim/generic/group2_device.hpp"
#include "bridge/cip/general_status.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"
#include "bridge/devicenet/wire/offline_connection.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"
#include "bridge/profiles/cdn127/objects.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::sim {

// An instance attribute of a class, on every instance of it.
struct ClassAttribute {
  std::uint16_t class_id = 0;
  std::uint8_t attribute = 0;
  friend bool operator==(const ClassAttribute&, const ClassAttribute&) = default;
};

// DOP attributes 5..8. The manual's encoding: action 0 = use the value, 1 = hold.
struct DopSettings {
  bool fault_hold = false;
  bool fault_value = false;
  bool idle_hold = false;
  bool idle_value = false;
  friend bool operator==(const DopSettings&, const DopSettings&) = default;
};

// AOP attributes 9..12: state 0 hold, 1 low (0 V), 2 high (4095), 3 the value.
struct AopSettings {
  std::uint8_t fault_state = 0;
  std::uint8_t idle_state = 0;
  std::uint16_t fault_value = 0;
  std::uint16_t idle_value = 0;
  friend bool operator==(const AopSettings&, const AopSettings&) = default;
};

// What every output does on a fault and on idle: DOP instances 1 (Pump On)
// and 2 (N2 Ballast On) attributes 5..8, AOP attributes 9..12.
struct OutputActions {
  std::array<DopSettings, 2> dop{};
  AopSettings aop{};
  friend bool operator==(const OutputActions&, const OutputActions&) = default;
};

// A device that leaves every output as it is when its master goes idle or
// away: DOP fault and idle actions 1 (no change), AOP fault and idle states 0
// (hold the last value). A pump that was on stays on.
inline constexpr OutputActions kUnsafeFactoryOutputActions{
    .dop = {DopSettings{.fault_hold = true, .idle_hold = true},
            DopSettings{.fault_hold = true, .idle_hold = true}},
    .aop = AopSettings{.fault_state = 0, .idle_state = 0},
};

struct SlaveOptions {
  // Front-panel rotary switches, read at power-up only (manual, "Switches"):
  // MAC 0..63 valid, 64..99 the program position (MAC set in software); baud
  // 0..2 valid (125k, 250k, 500k), 3..9 the program position.
  std::uint8_t mac_switch = 99;
  std::uint8_t baud_switch = 9;
  // Software MAC and baud held in E2 before the first power-up.
  std::uint8_t stored_mac = 63;
  std::uint8_t stored_baud = 0;

  std::uint8_t revision_major = 1;
  std::uint8_t revision_minor = 5;
  std::uint8_t hardware_major = 1;
  std::uint8_t hardware_minor = 0;
  // The manual types Identity attribute 6 as UINT (2 bytes): false, the low
  // 16 bits of serial_number; the ODVA Identity object has UDINT (4 bytes):
  // true. The duplicate MAC message carries 4 either way.
  std::uint32_t serial_number = 0x00001234;
  bool serial_number_udint = false;
  // Device Supervisor attribute 12 bit 7 "1 == Expanded Mode", also in the
  // poll response's DSUP byte.
  bool report_expanded_mode = true;
  // The manual lists the explicit connection's attribute 12 as Get, "fixed
  // value" 1; some devices accept 1 or 3.
  bool explicit_timeout_action_settable = false;
  // Expected packet rates are rounded up to this (bridge/PROTOCOL.md §7); the
  // Set answers the rate kept (2 bytes). 100 ms: a coarse device.
  Duration timer_resolution = milliseconds(10);
  // Configuration object values in E2 before the first power-up.
  profiles::cdn127::IoConfiguration configuration =
      profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn127);
  // The outputs' fault and idle actions in E2 before the first power-up, and
  // what Identity Reset type 1 restores. The manual gives no factory values.
  // By default each DOP goes to its value, Off, on a fault and on idle
  // (action 0, value 0) and the AOP holds its last value (state 0): every
  // attribute 0. kUnsafeFactoryOutputActions is the device a master must
  // not trust as it comes: it keeps the pump on.
  OutputActions factory_output_actions{};

  PumpModel::Config pump{};
  Duration duplicate_mac_window = seconds(1);
  Duration fragment_ack_timeout = seconds(1);
  OfflineOptions offline{};
  // Attributes this device's firmware does not implement although the
  // manual lists them: Get and Set answer 0x14 (attribute not supported), as
  // for any attribute a device has not. {{0x05, 7}, {0x05, 8}} is a
  // firmware without the poll connection's Produced/Consumed Size, which
  // leaves a master the Configuration object's Number Produced/Consumed;
  // {{0x01, 8}} one without the Identity's State.
  std::vector<ClassAttribute> unsupported_attributes;
  // Attributes this device's firmware has Get only although the manual lists
  // them Get/Set: Get answers as usual, Set answers 0x0E (attribute not
  // settable). {{0x0B, 9}} is a firmware whose analog output's Fault State
  // cannot be changed over the network, which a master downloading the safe
  // state must report rather than go on with the device's own.
  std::vector<ClassAttribute> read_only_attributes;

  // --- Readings of the manual that field devices took. Each off (zero) by
  // default: the reading this simulator takes otherwise.

  // Configuration object NOTE 1, "may only be set when the POLL connection
  // is not in the RUNNING state", read strictly: Set_Attribute_Single of its
  // attributes 1..5 and 10 and its Reset are refused with 0x0C (object state
  // conflict) while the poll connection exists at all (allocated, in any
  // state but Non-existent). Off: refused only while it is Established.
  bool configuration_locked_while_poll_allocated = false;
  // The Connection object's instance 2 table lists attributes 14 (produced
  // path) and 16 (consumed path) as Get: a Set of either answers 0x0E
  // (attribute not settable) in every state, and the poll connection keeps
  // the default assemblies (103 produced, 104 consumed) whose formats follow
  // the Configuration object. Off: settable while Configuring, as the
  // Assembly section's "by writing the corresponding DeviceNet Path
  // information" reads.
  bool poll_paths_fixed = false;
  // A poll command shorter than the consumed size (the idle condition,
  // manual "Poll Packet Sizes") applies the idle actions and is answered
  // with a zero-length poll response. Off: answered with the full produced
  // data, as any poll.
  bool idle_poll_answered_empty = false;
  // A request in acknowledged fragments: every fragment is acked but the
  // last, which the response itself answers (sent at once, no ack before
  // it). Off: the last fragment is acked too, then the response follows
  // (bridge/PROTOCOL.md §5: the receiver acks every fragment, the last
  // included).
  bool no_ack_of_last_request_fragment = false;
  // A Release of an established poll connection leaves the outputs as they
  // are (the manual names no action for it; a master must idle them first).
  // Off: the outputs take their idle values, as on an idle poll.
  bool release_keeps_outputs = false;
  // A slow device: every explicit response (success or error, on the
  // explicit connection or the unconnected port: Allocate/Release answers
  // included) goes out this long after its request arrived, and every poll
  // response this long after its poll command; in order. The request itself
  // takes effect on arrival; fragment acks and the later fragments of a
  // fragmented response (which answer the master's acks) are not delayed.
  // Zero: at once.
  Duration explicit_response_delay = Duration::zero();
  Duration poll_response_delay = Duration::zero();
};

// Every reading above at once, the strictest device a master may meet:
// configuration locked while the poll connection exists, fixed poll paths,
// idle polls answered empty, no ack of a request's last fragment, outputs
// kept on a Release of the poll connection, explicit
// responses 300 ms and poll responses 3 ms late, the 2-byte (UINT) serial
// number, no Identity State attribute (0x01/8), expected packet rates in
// steps of 100 ms. What `cdn127-sim --reading field` runs.
// The factory output actions are left as they are: they are not a reading of
// the manual but values in E2, and a device in the field holds whatever the
// last configuration tool wrote there, safe or not. Choose them on their own
// (factory_output_actions) to try either with any reading.
void apply_field_reading(SlaveOptions& options);

// What the CDN127 keeps in E2 across power cycles. The manual says so for the
// Configuration object (NOTE 1) and the software MAC/baud ("defaults to the
// last hardware setting"); the fault/idle settings, BOI and the alarm/warning
// enables are kept too, as parameters of a device are.
struct E2Memory {
  profiles::cdn127::IoConfiguration configuration{};
  std::uint8_t mac = 63;
  std::uint8_t baud = 0;
  bool bus_off_interrupt = false;
  std::array<DopSettings, 2> dop{};
  AopSettings aop{};
  bool alarm_enable = true;
  bool warning_enable = true;
};

// Identity attribute 5 bits 8..11 (ODVA numbering; the manual lists 8/9 twice).
// A recoverable fault lasts as long as its cause, which is outside the device
// (a short on a DOP, the +24 Vdc gone): it stays until cleared, power cycles
// included. An unrecoverable one lasts until the next power cycle, "the only
// exit from a Major Unrecoverable fault condition" (manual, Identity
// attribute 8); the manual names no exit for the minor one, which is taken to
// be the same. An Identity Reset is no power cycle: it clears neither.
struct IdentityFaults {
  bool minor_recoverable = false;  // DOP short circuit
  bool minor_unrecoverable = false;
  bool major_recoverable = false;    // loss of +24 Vdc
  bool major_unrecoverable = false;  // checksum, A/D

  bool major() const noexcept { return major_recoverable || major_unrecoverable; }
  friend bool operator==(const IdentityFaults&, const IdentityFaults&) = default;
};

inline constexpr std::uint16_t kExplicitMessageSize = 24;  // attributes 7/8 of instance 1

// The CDN127's assemblies (manual, "Assembly Object"): produced 1, 2, 3,
// 101, 102, 103; consumed 5, 100, 104.
constexpr bool is_produced_assembly(std::uint16_t a) noexcept {
  return a == 1 || a == 2 || a == 3 || a == 101 || a == 102 || a == 103;
}
constexpr bool is_consumed_assembly(std::uint16_t a) noexcept {
  return a == 5 || a == 100 || a == 104;
}

class Cdn127Device final : private ConnectionEvents, public IoAssemblies {
 public:
  explicit Cdn127Device(const SlaveOptions& options) noexcept;
  Cdn127Device(const Cdn127Device&) = delete;
  Cdn127Device& operator=(const Cdn127Device&) = delete;

  // Power-up: volatile state cleared, switches read, outputs off; with
  // power applied, the unrecoverable faults end too (IdentityFaults). E2
  // persists. Under a recoverable major fault still standing the outputs
  // stay off until it clears: fault actions act on the change to a fault.
  void power_up(TimePoint now, PowerUpCause cause) noexcept;
  // Identity Reset type 1: E2 back to the out-of-box values.
  void restore_factory_defaults() noexcept;

  const SlaveOptions& options() const noexcept { return options_; }
  E2Memory& e2() noexcept { return e2_; }
  const E2Memory& e2() const noexcept { return e2_; }
  PumpModel& pump() noexcept { return pump_; }
  const PumpModel& pump() const noexcept { return pump_; }

  // --- DeviceNet object ---
  devicenet::MacId mac() const noexcept { return mac_; }
  std::uint8_t baud() const noexcept { return baud_; }
  void set_switches(std::uint8_t mac_switch, std::uint8_t baud_switch) noexcept;
  std::uint8_t mac_switch() const noexcept { return mac_switch_; }
  std::uint8_t baud_switch() const noexcept { return baud_switch_; }
  bool mac_switch_in_program_position() const noexcept {
    return mac_switch_ > devicenet::MacId::kMax;
  }
  bool baud_switch_in_program_position() const noexcept { return baud_switch_ > 2; }
  bool mac_switch_changed() const noexcept { return mac_switch_ != mac_switch_at_power_up_; }
  bool baud_switch_changed() const noexcept { return baud_switch_ != baud_switch_at_power_up_; }
  std::uint8_t bus_off_counter() const noexcept { return bus_off_counter_; }
  void clear_bus_off_counter() noexcept { bus_off_counter_ = 0; }
  Reply set_mac(std::uint8_t mac) noexcept;
  Reply set_baud(std::uint8_t baud) noexcept;

  // --- allocation (bridge/PROTOCOL.md §3) and the Connection object ---
  ConnectionSet& connections() noexcept { return connections_; }
  const ConnectionSet& connections() const noexcept { return connections_; }
  // 255 when no master owns the connection set.
  std::uint8_t owner() const noexcept { return connections_.owner(); }
  bool owned() const noexcept { return connections_.owned(); }
  std::uint8_t allocation_choice() const noexcept { return connections_.allocation_choice(); }
  const Connection& explicit_connection() const noexcept {
    return connections_.explicit_connection();
  }
  const Connection& poll_connection() const noexcept { return connections_.poll_connection(); }
  bool explicit_established() const noexcept { return connections_.explicit_established(); }
  // Connection attributes 7/8: the explicit connection's message size, the
  // poll connection's assemblies as the Configuration object lays them out.
  std::uint16_t connection_size(std::uint16_t instance, bool produced) const noexcept override;
  bool assembly_allowed(std::uint16_t instance, bool produced,
                        std::uint16_t assembly) const noexcept override;
  std::uint32_t max_assembly() const noexcept override { return 0xFF; }
  // The Connection table lists 14/16 as Get, but the Assembly section selects
  // the poll assemblies "by writing the corresponding DeviceNet Path
  // information" to them: settable while Configuring, unless
  // SlaveOptions::poll_paths_fixed.
  bool paths_fixed() const noexcept override { return options_.poll_paths_fixed; }

  // --- poll I/O ---
  PollResult on_poll(Bytes command, TimePoint now) noexcept;
  // Produced assembly data (1, 2, 3, 101, 102, 103) as sampled at `now`;
  // 0 if not produced.
  std::size_t produced_data(std::uint8_t assembly, TimePoint now, MutableBytes out) noexcept;
  std::size_t consumed_data(std::uint8_t assembly, MutableBytes out) const noexcept;
  Reply set_consumed_assembly(std::uint8_t assembly, Bytes data, TimePoint now) noexcept;

  // --- outputs ---
  // Outputs set over the network (DOP State): refused with 0x10 (device
  // state conflict) while a major fault stands.
  Reply set_outputs(const profiles::cdn127::PumpOutputs& outputs, OutputCause cause,
                    TimePoint now) noexcept;
  void apply_fault_actions(TimePoint now) noexcept;
  // Nothing while a major fault stands: the outputs keep their fault state.
  void apply_idle_actions(TimePoint now) noexcept;

  // --- Configuration object ---
  const profiles::cdn127::IoConfiguration& configuration() const noexcept {
    return e2_.configuration;
  }
  // Refused with 0x0C while the poll connection is established (manual,
  // NOTE 1), or while it exists at all with
  // SlaveOptions::configuration_locked_while_poll_allocated.
  Reply set_configuration(const profiles::cdn127::IoConfiguration& config) noexcept;

  // --- Identity / Device Supervisor ---
  std::uint16_t identity_status() const noexcept;
  std::uint8_t identity_state() const noexcept;
  std::uint8_t supervisor_device_status() const noexcept;
  std::uint8_t exception_status_byte() noexcept;
  // The device's faults as they are now. A major fault where there was none
  // applies the fault actions (DOP attribute 5, AOP attribute 9) and then
  // holds the outputs there until every major fault has cleared: polls are
  // answered but not applied, DOP State and consumed assembly Sets refused.
  // The manual's Identity section says nothing of the outputs; its AOP Fault
  // State applies on fault conditions that "include software conditions
  // (connection timeout)", so not only those. Minor faults change no output.
  void set_faults(const IdentityFaults& faults, TimePoint now) noexcept;
  const IdentityFaults& faults() const noexcept { return faults_; }
  bool major_fault() const noexcept { return faults_.major(); }
  // A failed converter: the channel's poll response field carries `raw`
  // whatever it is (above 4095 included) until cleared with nullopt.
  void fail_analog_input(std::size_t channel, std::optional<std::uint16_t> raw) noexcept {
    if (channel < failed_analog_.size()) failed_analog_[channel] = raw;
  }
  // The manufacturer detail bytes of Device Supervisor attributes 13/14.
  std::uint8_t alarm_detail() const noexcept;
  std::uint8_t warning_detail() const noexcept;

  void request_action(PendingAction a) noexcept { pending_ = a; }
  PendingAction take_pending_action() noexcept;

  // Communication Fault: connections and ownership dropped; a running poll
  // connection's outputs take their fault values.
  void go_offline(TimePoint now) noexcept;
  std::uint32_t watchdog_timeouts() const noexcept { return connections_.watchdog_timeouts(); }

  // --- time ---
  void on_timer(TimePoint now) noexcept;
  TimePoint next_deadline() const noexcept;

 private:
  // The poll connection's changes (ConnectionEvents).
  void on_io_established(std::uint16_t instance, TimePoint now) noexcept override;
  void on_io_rate_changed(std::uint16_t, TimePoint) noexcept override {}
  void on_io_released(std::uint16_t instance, const Connection& before,
                      TimePoint now) noexcept override;
  void on_io_timed_out(std::uint16_t instance, const Connection& before,
                       TimePoint now) noexcept override;
  void apply_decoded_outputs(const profiles::cdn127::PollRequestLayout& layout,
                             const profiles::cdn127::PumpOutputs& decoded, OutputCause cause,
                             TimePoint now) noexcept;
  // The inputs sampled at `now` (the pump advanced to it first).
  std::size_t build_produced(const profiles::cdn127::PollResponseLayout& layout, TimePoint now,
                             MutableBytes out) noexcept;

  SlaveOptions options_;
  E2Memory e2_;
  PumpModel pump_;

  devicenet::MacId mac_;
  std::uint8_t baud_ = 0;
  std::uint8_t mac_switch_;
  std::uint8_t baud_switch_;
  std::uint8_t mac_switch_at_power_up_;
  std::uint8_t baud_switch_at_power_up_;
  std::uint8_t bus_off_counter_ = 0;

  ConnectionSet connections_;
  bool poll_running_ = false;  // a full poll since the poll connection was established

  IdentityFaults faults_;
  std::array<std::optional<std::uint16_t>, 2> failed_analog_{};
  PendingAction pending_ = PendingAction::kNone;
};

}  // namespace dnbridge::sim
