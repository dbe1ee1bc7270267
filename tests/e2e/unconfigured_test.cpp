// A node at a MAC the rack's configuration does not have (a MAC switch set
// wrong) is seen without a scan: PortStatus lists its MAC and the log says
// so, and the configured nodes are not disturbed.
#include "e2e/bridge_fixture.hpp"

namespace dnbridge::e2e {
namespace {

TEST_F(BridgeTest, ANodeAtAnUnconfiguredMacIsReportedOnPortStatus) {
  auto config = rack_config();
  config.ports.at(0).simulated_unconfigured = {*devicenet::MacId::from(17),
                                               *devicenet::MacId::from(42)};
  ASSERT_NO_FATAL_FAILURE(start_online(std::move(config)));
  const auto heard = [&] {
    const auto* p = ports_.latest([](const auto&) { return true; });
    if (!p) return std::vector<std::uint8_t>{};
    const auto macs = dds::view(p->unconfigured_macs);
    return std::vector<std::uint8_t>(macs.begin(), macs.end());
  };
  ASSERT_TRUE(ports_.until([&] { return heard().size() == 2; })) << heard().size();
  EXPECT_EQ(heard(), (std::vector<std::uint8_t>{17, 42}));
  EXPECT_TRUE(log_.contains(LogLevel::kWarn,
                            "a node at MAC 17, which the configuration does not have, was heard "
                            "checking its MAC ID (powering up)"));
  const auto* p = ports_.latest([](const auto&) { return true; });
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->nodes_online, kPumps);
  EXPECT_EQ(p->nodes_configured, kPumps);
}

}  // namespace
}  // namespace dnbridge::e2e
