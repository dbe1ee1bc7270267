// Size verification against a CDN127 firmware that refuses the poll
// connection's Produced/Consumed Size (Connection 2 attributes 7/8) with
// 0x14, attribute not supported: the master falls back to the Configuration
// object's Number Produced/Consumed (attributes 16/17; CDN127 manual,
// "Configuration Object": "Access to this attribute is not dependent on the
// Poll connection being created"). Master and simulated devices on the
// in-process bus, fake clock.
#include <gtest/gtest.h>

#include <string>

#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

constexpr unsigned kMac = 12;

// The firmware variants: without Connection 7/8, and without 16/17 as well.
const std::vector<sim::ClassAttribute> kNoConnectionSizes = {{0x05, 7}, {0x05, 8}};
const std::vector<sim::ClassAttribute> kNoSizesAtAll = {
    {0x05, 7}, {0x05, 8}, {0x40, 16}, {0x40, 17}};

constexpr const char* kProducedFallback = "Configuration (class 0x40) instance 1 attribute 16";
constexpr const char* kConsumedFallback = "Configuration (class 0x40) instance 1 attribute 17";

class SizeFallback : public ::testing::Test {
 protected:
  // One CDN127 at kMac whose firmware lacks `unsupported`; the scan list as
  // rack_config() makes it, then `adjust`ed.
  void build(std::vector<sim::ClassAttribute> unsupported,
             std::function<void(devicenet::ScannerConfig&)> adjust = {}) {
    auto config = rack_config({kMac});
    config.create_devices = false;
    config.adjust_scan_list = std::move(adjust);
    rack_ = std::make_unique<sim::SimRack>(std::move(config));
    rack_->observe(events_);
    sim::SlaveOptions options = sim::default_slave_options(mac(kMac));
    options.unsupported_attributes = std::move(unsupported);
    rack_->add_device(std::move(options), std::nullopt);
    rack_->start();
  }
  bool run_until(NodeState state) {
    return rack_->world().run_until([&] { return view().state == state; }, seconds(10));
  }
  const rack::PumpView& view() { return *rack_->pumps().pump(mac(kMac)); }
  const devicenet::Node& node() { return *rack_->scanner().node(mac(kMac)); }
  sim::Cdn127Slave& device() { return rack_->device(mac(kMac)).device(); }

  std::unique_ptr<sim::SimRack> rack_;
  EventRecorder events_;
};

TEST_F(SizeFallback, SizesReadFromTheConfigurationObjectAndTheNodeGoesOnline) {
  build(kNoConnectionSizes);
  ASSERT_TRUE(run_until(NodeState::kOnline)) << view().reason;
  // The CDN127 preset: 6 B in (DSUP DIN AIN AIN), 4 B out (DOUT PAD AOUT).
  EXPECT_NE(view().reason.find("4 B out, 6 B in"), std::string::npos) << view().reason;
  EXPECT_NE(view().reason.find(kProducedFallback), std::string::npos) << view().reason;
  EXPECT_NE(view().reason.find(kConsumedFallback), std::string::npos) << view().reason;
  // Attribute 7 refused once; 8 never asked after that (nor anything else refused).
  EXPECT_EQ(device().counters().requests_refused, 1u);

  // Polled with those sizes: inputs decoded, commanded outputs applied.
  rack_->world().run_for(milliseconds(500));
  EXPECT_GT(node().counters().polls, 3u);
  EXPECT_TRUE(view().has_inputs);
  profiles::cdn127::PumpOutputs out;
  out.pump_on = true;
  out.analog_out_raw = 2048;
  ASSERT_TRUE(rack_->pumps().command(mac(kMac), out, rack_->now()).ok());
  rack_->world().run_for(milliseconds(300));
  EXPECT_EQ(device().outputs(), out);
  EXPECT_EQ(view().state, NodeState::kOnline);
}

TEST_F(SizeFallback, FallbackRefusedTooIsAConfigurationFaultNamingBothAttributes) {
  build(kNoSizesAtAll);
  ASSERT_TRUE(run_until(NodeState::kConfigurationFault)) << view().reason;
  const std::string& reason = view().reason;
  EXPECT_NE(reason.find("cannot read the poll produced size"), std::string::npos) << reason;
  EXPECT_NE(reason.find("Connection 2 attribute 7: attribute not supported (0x14/0xFF)"),
            std::string::npos)
      << reason;
  EXPECT_NE(reason.find(std::string("fallback ") + kProducedFallback +
                        ": attribute not supported (0x14/0xFF)"),
            std::string::npos)
      << reason;
  EXPECT_EQ(node().counters().polls, 0u);
  // Left alone, not polled, through its re-checks.
  rack_->world().run_for(seconds(20));
  EXPECT_EQ(node().counters().polls, 0u);
  EXPECT_NE(view().state, NodeState::kOnline);
}

// Attribute 7 refused, 16 answered, 17 refused: the consumed size's own
// attribute (8) was never asked, and the reason says that rather than
// naming attribute 7's refusal as if it were 8's.
TEST_F(SizeFallback, ConsumedFallbackRefusedSaysItsOwnAttributeWasNotAsked) {
  build({{0x05, 7}, {0x05, 8}, {0x40, 17}});
  ASSERT_TRUE(run_until(NodeState::kConfigurationFault)) << view().reason;
  const std::string& reason = view().reason;
  EXPECT_NE(reason.find("cannot read the poll consumed size: Connection 2 attribute 8 not asked "
                        "(Connection 2 attribute 7: attribute not supported (0x14/0xFF))"),
            std::string::npos)
      << reason;
  EXPECT_NE(reason.find(std::string("fallback ") + kConsumedFallback +
                        ": attribute not supported (0x14/0xFF)"),
            std::string::npos)
      << reason;
  EXPECT_EQ(node().counters().polls, 0u);
}

TEST_F(SizeFallback, FallbackSizeThatDiffersIsAConfigurationFaultSayingWhereItWasRead) {
  // Expect one byte more than the device produces, as a scan list written
  // for another reading of the manual would.
  build(kNoConnectionSizes,
        [](devicenet::ScannerConfig& port) { port.nodes.at(0).profile.produced_size += 1; });
  ASSERT_TRUE(run_until(NodeState::kConfigurationFault)) << view().reason;
  const std::string& reason = view().reason;
  EXPECT_NE(reason.find(std::string("produces 6 B (") + kProducedFallback + ")"), std::string::npos)
      << reason;
  EXPECT_NE(reason.find(std::string("consumes 4 B (") + kConsumedFallback + ")"), std::string::npos)
      << reason;
  EXPECT_NE(reason.find("expects 7 B and 4 B"), std::string::npos) << reason;
  EXPECT_EQ(node().counters().polls, 0u);
}

// The device that answers Connection 2 attributes 7/8 never gets the
// fallback asked, and its reasons say so.
TEST_F(SizeFallback, ConnectionSizesAnsweredNeedNoFallback) {
  build({});
  ASSERT_TRUE(run_until(NodeState::kOnline)) << view().reason;
  EXPECT_EQ(view().reason.find("Configuration"), std::string::npos) << view().reason;
  EXPECT_EQ(device().counters().requests_refused, 0u);
}

}  // namespace
}  // namespace dnbridge::test
