// The simulated CDN127's pump (PumpModel) alone, no wire: running after
// spin-up and until spin-down, the interlock and the alarm, and the exception
// status gated by its enables.
#include "adapters/sim/cdn127/pump_model.hpp"

#include <gtest/gtest.h>

namespace dnbridge::sim {
namespace {

TEST(PumpModel, RunningFollowsPumpOnAfterSpinUpAndSpinDown) {
  PumpModel::Config c;
  c.spin_up = seconds(3);
  c.spin_down = seconds(5);
  PumpModel pump(c);
  TimePoint t{};
  pump.set_outputs({.pump_on = true, .n2_ballast_on = false, .analog_out_raw = 0},
                   OutputCause::kPoll, t);
  EXPECT_EQ(pump.next_deadline(), t + seconds(3));
  pump.advance(t + milliseconds(2999));
  EXPECT_FALSE(pump.running());
  pump.advance(t + seconds(3));
  EXPECT_TRUE(pump.running());
  pump.set_outputs({}, OutputCause::kPoll, t + seconds(10));
  pump.advance(t + milliseconds(14999));
  EXPECT_TRUE(pump.running());
  EXPECT_EQ(pump.motor(), PumpModel::Motor::kStopping);
  pump.advance(t + seconds(15));
  EXPECT_FALSE(pump.running());
  EXPECT_EQ(pump.next_deadline(), kNever);
}

TEST(PumpModel, SwitchedOffBeforeSpeedNeverRuns) {
  PumpModel pump;
  TimePoint t{};
  pump.set_outputs({.pump_on = true, .n2_ballast_on = false, .analog_out_raw = 0},
                   OutputCause::kPoll, t);
  pump.set_outputs({}, OutputCause::kPoll, t + seconds(1));
  pump.advance(t + seconds(10));
  EXPECT_FALSE(pump.running());
}

TEST(PumpModel, InterlockAndAlarmStopThePump) {
  PumpModel::Config c;
  c.spin_up = Duration::zero();
  c.spin_down = Duration::zero();
  PumpModel pump(c);
  TimePoint t{};
  pump.set_interlock_ok(false, t);
  pump.set_outputs({.pump_on = true, .n2_ballast_on = false, .analog_out_raw = 0},
                   OutputCause::kPoll, t);
  EXPECT_FALSE(pump.running());
  pump.set_interlock_ok(true, t);
  EXPECT_TRUE(pump.running());
  pump.set_alarm(true, t);
  EXPECT_FALSE(pump.running());
  EXPECT_TRUE(pump.inputs().alarm_active);
  EXPECT_FALSE(pump.set_analog_input(0, 4096));
  EXPECT_FALSE(pump.set_analog_input(2, 1));
}

TEST(PumpModel, ExceptionStatusGatedByEnables) {
  PumpModel pump;
  TimePoint t{};
  EXPECT_EQ(pump.exception_status(true, true).encode(), 0x00);
  pump.set_interlock_ok(false, t);
  EXPECT_EQ(pump.exception_status(true, true).encode(), 0x02);
  EXPECT_EQ(pump.exception_status(false, true).encode(), 0x00);
  pump.set_interlock_ok(true, t);
  pump.set_warning(true);
  EXPECT_EQ(pump.exception_status(true, true).encode(), 0x20);
  EXPECT_EQ(pump.exception_status(true, false).encode(), 0x00);
}

}  // namespace
}  // namespace dnbridge::sim
