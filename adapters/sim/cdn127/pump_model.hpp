#pragma once
// The dry vacuum pump behind a simulated CDN127: what the CDN127's outputs
// drive and what its inputs sense. Sans-IO: time is handed in.
//
// The motor follows the Pump On output after a spin-up delay and keeps turning
// for a spin-down delay after it is switched off. The pump only receives the
// On signal while the interlock is satisfied (manual, "CDN127 Interlock": the
// On/Off signal is routed through the interlock connector), and a pump in
// alarm ("Pump Fail") stops.
#include <array>
#include <cstdint>

#include "bridge/common/time.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"

namespace dnbridge::sim {

// Why the outputs last changed.
enum class OutputCause : std::uint8_t {
  kPowerUp,   // outputs off after power-up
  kPoll,      // a full poll command
  kExplicit,  // Set_Attribute_Single on a DOP, AOP or consumed assembly
  kIdle,      // idle actions (short poll command, or the poll connection released)
  kFault,     // fault actions (poll connection timed out)
};

class PumpModel {
 public:
  struct Config {
    Duration spin_up = seconds(3);
    Duration spin_down = seconds(5);
    // Pump On reaches the pump only while the interlock is satisfied.
    bool interlock_gates_pump = true;
    // A pump in alarm (Pump Fail) stops.
    bool alarm_stops_pump = true;
  };

  enum class Motor : std::uint8_t { kStopped, kStarting, kRunning, kStopping };

  PumpModel() noexcept : PumpModel(Config{}) {}
  explicit PumpModel(Config config) noexcept : config_(config) {}

  // --- the CDN127's outputs ---
  void set_outputs(const profiles::cdn127::PumpOutputs& outputs, OutputCause cause,
                   TimePoint now) noexcept;
  const profiles::cdn127::PumpOutputs& outputs() const noexcept { return outputs_; }
  OutputCause last_cause() const noexcept { return cause_; }
  bool pump_on() const noexcept { return outputs_.pump_on; }
  bool n2_ballast_on() const noexcept { return outputs_.n2_ballast_on; }
  std::uint16_t analog_out_raw() const noexcept { return outputs_.analog_out_raw; }
  // True when the last change came from a fault or idle action.
  bool last_change_was_fault() const noexcept { return cause_ == OutputCause::kFault; }
  bool last_change_was_idle() const noexcept { return cause_ == OutputCause::kIdle; }

  // --- the pump's signals, driven by tests ---
  void set_interlock_ok(bool ok, TimePoint now) noexcept;
  void set_alarm(bool active, TimePoint now) noexcept;  // "Pump Fail" / "Pump Alarm"
  void set_warning(bool active) noexcept { warning_ = active; }
  void set_n2_flow_ok(bool ok) noexcept { n2_flow_ok_ = ok; }
  // Refuses values over 4095 (returns false): the ADC has 12 bits.
  bool set_analog_input(std::size_t channel, std::uint16_t raw) noexcept;

  // --- what the CDN127's inputs sense ---
  // Advances the motor to `now`; call before reading running()/inputs().
  void advance(TimePoint now) noexcept;
  TimePoint next_deadline() const noexcept;
  Motor motor() const noexcept { return motor_; }
  bool running() const noexcept { return motor_ == Motor::kRunning || motor_ == Motor::kStopping; }
  bool interlock_ok() const noexcept { return interlock_ok_; }
  bool alarm_active() const noexcept { return alarm_; }
  bool warning_active() const noexcept { return warning_; }
  bool n2_flow_ok() const noexcept { return n2_flow_ok_; }
  profiles::cdn127::PumpInputs inputs() const noexcept;
  const std::array<std::uint16_t, 2>& analog_inputs_raw() const noexcept { return analog_in_; }

  // Device Specific Error if N2 flow failed, the pump is in alarm or the
  // interlock failed ("Pump Fail Interlock"); Device Specific Warning if the
  // pump warns (manual, Assembly note (1)). Each gated by its enable (Device
  // Supervisor attributes 15/16: clearing an enable clears its bits).
  profiles::cdn127::ExceptionStatus exception_status(bool alarm_enable,
                                                     bool warning_enable) const noexcept;

 private:
  bool drive() const noexcept;
  void update_drive(TimePoint now) noexcept;

  Config config_;
  profiles::cdn127::PumpOutputs outputs_{};
  OutputCause cause_ = OutputCause::kPowerUp;
  Motor motor_ = Motor::kStopped;
  TimePoint motor_deadline_ = kNever;
  bool interlock_ok_ = true;
  bool alarm_ = false;
  bool warning_ = false;
  bool n2_flow_ok_ = true;
  std::array<std::uint16_t, 2> analog_in_{};
};

}  // namespace dnbridge::sim
