#include "adapters/sim/cdn127/pump_model.hpp"

namespace dnbridge::sim {

using profiles::cdn127::ExceptionStatus;
using profiles::cdn127::PumpInputs;
using profiles::cdn127::PumpOutputs;

void PumpModel::set_outputs(const PumpOutputs& outputs, OutputCause cause, TimePoint now) noexcept {
  advance(now);
  outputs_ = outputs;
  cause_ = cause;
  update_drive(now);
}

void PumpModel::set_interlock_ok(bool ok, TimePoint now) noexcept {
  advance(now);
  interlock_ok_ = ok;
  update_drive(now);
}

void PumpModel::set_alarm(bool active, TimePoint now) noexcept {
  advance(now);
  alarm_ = active;
  update_drive(now);
}

bool PumpModel::set_analog_input(std::size_t channel, std::uint16_t raw) noexcept {
  if (channel >= analog_in_.size() || raw > profiles::cdn127::kAnalogMaxRaw) return false;
  analog_in_[channel] = raw;
  return true;
}

bool PumpModel::drive() const noexcept {
  if (!outputs_.pump_on) return false;
  if (config_.interlock_gates_pump && !interlock_ok_) return false;
  if (config_.alarm_stops_pump && alarm_) return false;
  return true;
}

void PumpModel::update_drive(TimePoint now) noexcept {
  if (drive()) {
    switch (motor_) {
      case Motor::kStopped:
        if (config_.spin_up <= Duration::zero()) {
          motor_ = Motor::kRunning;
          motor_deadline_ = kNever;
        } else {
          motor_ = Motor::kStarting;
          motor_deadline_ = now + config_.spin_up;
        }
        break;
      case Motor::kStopping:  // still turning: back to speed at once
        motor_ = Motor::kRunning;
        motor_deadline_ = kNever;
        break;
      case Motor::kStarting:
      case Motor::kRunning:
        break;
    }
  } else {
    switch (motor_) {
      case Motor::kRunning:
        if (config_.spin_down <= Duration::zero()) {
          motor_ = Motor::kStopped;
          motor_deadline_ = kNever;
        } else {
          motor_ = Motor::kStopping;
          motor_deadline_ = now + config_.spin_down;
        }
        break;
      case Motor::kStarting:  // never reached speed: the Running input never came on
        motor_ = Motor::kStopped;
        motor_deadline_ = kNever;
        break;
      case Motor::kStopping:
      case Motor::kStopped:
        break;
    }
  }
}

void PumpModel::advance(TimePoint now) noexcept {
  if (now < motor_deadline_) return;
  if (motor_ == Motor::kStarting) motor_ = Motor::kRunning;
  if (motor_ == Motor::kStopping) motor_ = Motor::kStopped;
  motor_deadline_ = kNever;
}

TimePoint PumpModel::next_deadline() const noexcept { return motor_deadline_; }

PumpInputs PumpModel::inputs() const noexcept {
  PumpInputs in;
  in.pump_running = running();
  in.warning_active = warning_;
  in.n2_flow_ok = n2_flow_ok_;
  in.alarm_active = alarm_;
  in.interlock_ok = interlock_ok_;
  return in;
}

ExceptionStatus PumpModel::exception_status(bool alarm_enable, bool warning_enable) const noexcept {
  ExceptionStatus s;
  s.alarm_device_specific = alarm_enable && (!n2_flow_ok_ || alarm_ || !interlock_ok_);
  s.warning_device_specific = warning_enable && warning_;
  return s;
}

}  // namespace dnbridge::sim
