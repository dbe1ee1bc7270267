#pragma once
// When a node's state is worth a new sample. A pump's: at once on any
// change of a discrete value (online, inputs, alarms, outputs, idle, who
// commands), on an analog change larger than the deadband. A device's
// (profile "eds"): at once on any change of its data or of those states (its
// EDS says nothing of which bits are analog). Either in any case once per
// maximum period, so that readers can hold the bridge to a deadline.
#include <array>
#include <cstdint>
#include <string>

#include "bridge/common/time.hpp"
#include "bridge/rack/device_rack.hpp"
#include "bridge/rack/pump_rack.hpp"

namespace dnbridge::rack {

struct PublishPolicy {
  Duration max_period = seconds(1);
  double analog_deadband_volts = 0.05;  // pumps only

  friend bool operator==(const PublishPolicy&, const PublishPolicy&) = default;
};

// A node's gate, whatever its profile; its profile's rack makes it
// (ProfileNodes::state_gate) and gives it that profile's views only. The
// base keeps the maximum period; a profile's gate says only what in its
// view is news (changed) and what it keeps of a published one (record).
class StateGate {
 public:
  explicit StateGate(PublishPolicy policy) : policy_(policy) {}
  virtual ~StateGate() = default;
  // True if `view` differs enough from what was last published, or the
  // maximum period has passed.
  bool due(const NodeView& view, TimePoint now) const {
    return !published_once_ || now >= deadline() || changed(view);
  }
  void published(const NodeView& view, TimePoint now) {
    published_once_ = true;
    last_time_ = now;
    record(view);
  }
  // When the maximum period next forces a sample (kNever before the first).
  TimePoint deadline() const { return published_once_ ? last_time_ + policy_.max_period : kNever; }
  const PublishPolicy& policy() const { return policy_; }

 private:
  // Whether `view` differs enough from the one last recorded.
  virtual bool changed(const NodeView& view) const = 0;
  virtual void record(const NodeView& view) = 0;

  PublishPolicy policy_;
  bool published_once_ = false;
  TimePoint last_time_{};
};

class PumpStateGate final : public StateGate {
 public:
  using StateGate::StateGate;

 private:
  // Of a PumpView.
  bool changed(const NodeView& view) const override;
  void record(const NodeView& view) override;

  // The discrete part of a view: any difference is published.
  struct Discrete {
    bool online = false;
    bool inputs_valid = false;
    std::uint8_t input_bits = 0;
    std::uint8_t exception_bits = 0;
    bool has_exception = false;
    std::array<bool, 2> analog_in_range{};  // a channel turning invalid is news at once
    bool outputs_idle = true;
    profiles::cdn127::PumpOutputs outputs;
    friend bool operator==(const Discrete&, const Discrete&) = default;
  };
  static Discrete discrete(const PumpView& view);
  static std::array<int, 2> analog(const PumpView& view);

  Discrete last_;
  std::array<int, 2> last_analog_{-1, -1};
  std::string last_commander_;
};

class DeviceStateGate final : public StateGate {
 public:
  using StateGate::StateGate;

 private:
  // Of a DeviceView.
  bool changed(const NodeView& view) const override;
  void record(const NodeView& view) override;

  struct Seen {
    bool online = false;
    bool inputs_valid = false;
    std::vector<std::uint8_t> inputs;
    bool outputs_idle = true;
    std::vector<std::uint8_t> outputs;
    std::string commanded_by;
    friend bool operator==(const Seen&, const Seen&) = default;
  };
  static Seen seen(const DeviceView& view);

  Seen last_;
};

}  // namespace dnbridge::rack
