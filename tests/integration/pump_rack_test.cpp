// The rack model between the master and the DDS face: commands checked
// before they reach the master, refusals reported, the no-commander policy.
#include "bridge/rack/pump_rack.hpp"

#include <gtest/gtest.h>

#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

namespace cdn127 = profiles::cdn127;

TEST(PumpRack, RefusedCommandsAreCountedWithTheirReasonAndNothingIsApplied) {
  auto config = rack_config({1, 2});
  // Node 2 has no analog output in its configuration.
  config.pumps[1].io.num_analog_outputs = 0;
  sim::SimRack rack(config);
  rack.start();
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(20)));

  cdn127::PumpOutputs good;
  good.pump_on = true;
  good.analog_out_raw = 100;
  ASSERT_TRUE(rack.pumps().command(mac(1), good, "supervisor-a", rack.now()).ok());
  rack.world().run_for(milliseconds(200));

  cdn127::PumpOutputs bad = good;
  bad.analog_out_raw = 5000;
  EXPECT_EQ(rack.pumps().command(mac(1), bad, "supervisor-b", rack.now()).error(),
            Errc::kOutOfRange);
  rack.world().run_for(milliseconds(200));
  const auto& v1 = *rack.pumps().pump(mac(1));
  EXPECT_EQ(v1.commands_accepted, 1u);
  EXPECT_EQ(v1.commands_refused, 1u);
  EXPECT_NE(v1.last_command_refused.find("supervisor-b"), std::string::npos)
      << v1.last_command_refused;
  EXPECT_NE(v1.last_command_refused.find("5000"), std::string::npos) << v1.last_command_refused;
  // The refused command changed nothing: the accepted one stays in force.
  EXPECT_EQ(rack.device(mac(1)).device().outputs(), good);
  EXPECT_EQ(v1.commanded_by, "supervisor-a");

  EXPECT_EQ(rack.pumps().command(mac(2), good, "supervisor-a", rack.now()).error(),
            Errc::kUnsupported);
  EXPECT_NE(rack.pumps().pump(mac(2))->last_command_refused.find("no analog output"),
            std::string::npos);
  EXPECT_FALSE(rack.device(mac(2)).device().outputs().pump_on);  // not applied half

  EXPECT_EQ(rack.pumps().command(mac(40), good, "x", rack.now()).error(), Errc::kOutOfRange);
}

TEST(PumpRack, NoCommanderPolicyIdleOrHold) {
  auto config = rack_config({1, 2});
  config.pumps[1].no_commander = rack::NoCommanderPolicy::kHoldLastOutputs;
  sim::SimRack rack(config);
  rack.start();
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(20)));
  cdn127::PumpOutputs on;
  on.pump_on = true;
  for (unsigned m : {1u, 2u}) ASSERT_TRUE(rack.pumps().command(mac(m), on, "s", rack.now()).ok());
  rack.world().run_for(milliseconds(200));
  for (unsigned m : {1u, 2u}) ASSERT_TRUE(rack.pumps().release_command(mac(m), rack.now()).ok());
  rack.world().run_for(milliseconds(300));
  EXPECT_TRUE(rack.pumps().pump(mac(1))->outputs_idle);
  EXPECT_FALSE(rack.device(mac(1)).device().outputs().pump_on);
  EXPECT_FALSE(rack.pumps().pump(mac(2))->outputs_idle);
  EXPECT_TRUE(rack.device(mac(2)).device().outputs().pump_on);
}

TEST(PumpRack, InputsAreInvalidUntilAResponseAfterReconnection) {
  sim::SimRack rack(rack_config({3}));
  rack.start();
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(20)));
  rack.world().run_for(milliseconds(300));
  EXPECT_TRUE(rack.pumps().pump(mac(3))->has_inputs);
  rack.device(mac(3)).disconnect();
  rack.world().run_until([&] { return !rack.pumps().pump(mac(3))->online; }, seconds(5));
  EXPECT_FALSE(rack.pumps().pump(mac(3))->has_inputs);
}

}  // namespace
}  // namespace dnbridge::test
