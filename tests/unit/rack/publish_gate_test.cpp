#include "bridge/rack/publish_gate.hpp"

#include <gtest/gtest.h>

namespace dnbridge::rack {
namespace {

PumpView online_view() {
  PumpView v;
  v.online = true;
  v.has_inputs = true;
  v.inputs.input_bits = 0x1F;
  v.inputs.analog_inputs_raw = {std::uint16_t{1000}, std::uint16_t{2000}};
  v.inputs.analog_input_in_range = {true, true};
  return v;
}

const TimePoint t0 = TimePoint{} + seconds(100);

TEST(PumpStateGate, FirstSampleAndMaxPeriod) {
  PumpStateGate gate({seconds(1), 0.05});
  auto v = online_view();
  EXPECT_TRUE(gate.due(v, t0));
  EXPECT_EQ(gate.deadline(), kNever);
  gate.published(v, t0);
  EXPECT_EQ(gate.deadline(), t0 + seconds(1));
  EXPECT_FALSE(gate.due(v, t0 + milliseconds(999)));
  EXPECT_TRUE(gate.due(v, t0 + seconds(1)));
}

TEST(PumpStateGate, DiscreteChangesAreDueAtOnce) {
  PumpStateGate gate({seconds(10), 0.05});
  auto v = online_view();
  gate.published(v, t0);
  auto changed = v;
  changed.inputs.input_bits = 0x1E;  // pump stopped
  EXPECT_TRUE(gate.due(changed, t0 + milliseconds(1)));
  changed = v;
  changed.outputs_idle = false;
  EXPECT_TRUE(gate.due(changed, t0 + milliseconds(1)));
  changed = v;
  changed.online = false;
  EXPECT_TRUE(gate.due(changed, t0 + milliseconds(1)));
  changed = v;
  changed.commanded_by = "supervisor";
  EXPECT_TRUE(gate.due(changed, t0 + milliseconds(1)));
  changed = v;
  changed.inputs.exception_status = profiles::cdn127::ExceptionStatus::decode(0x02);
  EXPECT_TRUE(gate.due(changed, t0 + milliseconds(1)));
  // A channel going off the scale by a few counts, inside the deadband: its
  // validity changed, which is news.
  changed = v;
  changed.inputs.analog_inputs_raw[0] = std::uint16_t{4096};
  changed.inputs.analog_input_in_range[0] = false;
  auto near = v;
  near.inputs.analog_inputs_raw[0] = std::uint16_t{4094};
  gate.published(near, t0);
  EXPECT_TRUE(gate.due(changed, t0 + milliseconds(1)));
}

TEST(PumpStateGate, AnalogChangesWithinTheDeadbandWait) {
  PumpStateGate gate({seconds(10), 0.05});  // 0.05 V is about 20 counts
  auto v = online_view();
  gate.published(v, t0);
  auto small = v;
  small.inputs.analog_inputs_raw[0] = std::uint16_t{1015};  // 0.037 V
  EXPECT_FALSE(gate.due(small, t0 + milliseconds(1)));
  auto large = v;
  large.inputs.analog_inputs_raw[1] = std::uint16_t{2025};  // 0.061 V
  EXPECT_TRUE(gate.due(large, t0 + milliseconds(1)));
  // Drift is measured from what was published, not from the last reading.
  gate.published(v, t0);
  small.inputs.analog_inputs_raw[0] = std::uint16_t{1019};
  EXPECT_FALSE(gate.due(small, t0 + milliseconds(2)));
  small.inputs.analog_inputs_raw[0] = std::uint16_t{1022};
  EXPECT_TRUE(gate.due(small, t0 + milliseconds(3)));
}

TEST(PumpStateGate, ZeroDeadbandPublishesEveryAnalogChange) {
  PumpStateGate gate({seconds(10), 0.0});
  auto v = online_view();
  gate.published(v, t0);
  v.inputs.analog_inputs_raw[0] = std::uint16_t{1001};
  EXPECT_TRUE(gate.due(v, t0 + milliseconds(1)));
}

}  // namespace
}  // namespace dnbridge::rack
