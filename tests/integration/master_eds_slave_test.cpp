// A simulated slave described by the example I/O block EDS on the in-process
// bus, fake clock: the product's master brings it online exactly as it does a
// CDN127 (allocation, identity, paths, sizes, expected packet rates) and polls
// it; the poll response is the input assembly, the poll command lands in the
// output assembly's parameters, an idle poll and a lost connection take the
// outputs to zero; Release and the watchdog behave as the CDN127's. The
// simulated slave alone, frame by frame, is tested in
// tests/sim/generic/eds_slave_test.cpp.
#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "adapters/sim/generic/eds_slave.hpp"
#include "adapters/sim/world/sim_eds_slave.hpp"
#include "adapters/sim/world/sim_master.hpp"
#include "adapters/sim/world/sim_world.hpp"
#include "support/example_eds.hpp"

namespace dnbridge::test {
namespace {

using devicenet::MacId;
using devicenet::NodeState;

constexpr unsigned kSlaveMac = 5;
constexpr unsigned kMasterMac = 0;
// Example I/O block: Assembly 100 (inputs: Param3 DI, Param5 status, Param2
// AI) and 150 (outputs: Param4 DO, a pad byte).
constexpr std::uint16_t kInputs = 100;
constexpr std::uint16_t kOutputs = 150;

MacId mac(unsigned v) { return MacId::from(v).value(); }

class Recorder final : public devicenet::ScannerObserver {
 public:
  void on_node_state(MacId, NodeState, NodeState to, const std::string& reason,
                     TimePoint) override {
    state = to;
    last_reason = reason;
  }
  void on_poll_response(MacId, Bytes data, TimePoint) override {
    last_response.assign(data.begin(), data.end());
    ++responses;
  }
  NodeState state = NodeState::kAbsent;
  std::string last_reason;
  std::vector<std::uint8_t> last_response;
  unsigned responses = 0;
};

// The master's profile of the node, filled by hand from the EDS: [Device],
// PollInfo's Input1 (Assembly 100, 4 bytes) and Output1 (Assembly 150, 2).
devicenet::NodeConfig eds_node() {
  devicenet::NodeConfig n;
  n.mac = mac(kSlaveMac);
  n.name = "io-block";
  n.profile.identity = {65001, 7, 1};
  n.profile.produced_path = {0x20, 0x04, 0x24, 0x64, 0x30, 0x03};
  n.profile.consumed_path = {0x20, 0x04, 0x24, 0x96, 0x30, 0x03};
  n.profile.produced_size = 4;
  n.profile.consumed_size = 2;
  n.profile.format_description = "Input1 4 B, Output1 2 B";
  n.poll_period = milliseconds(100);
  n.expected_packet_rate = milliseconds(400);
  return n;
}

class EdsSlaveOnTheBus : public ::testing::Test {
 protected:
  void start(sim::EdsSlaveOptions options = {},
             profiles::eds::EdsFile file = test::example_eds(test::kIoBlockEds)) {
    options.mac = kSlaveMac;
    options.serial_number = 0x0A0B0C0D;
    slave_.emplace(world_, std::move(file), options, world_.now());
    devicenet::ScannerConfig port;
    port.master_mac = mac(kMasterMac);
    port.nodes.push_back(eds_node());
    master_.emplace(world_, port, events_);
    master_->scanner().start(world_.now());
  }
  bool run_until_online() {
    return world_.run_until([&] { return events_.state == NodeState::kOnline; }, seconds(10));
  }
  sim::EdsSlave& slave() { return slave_->device(); }
  devicenet::Scanner& scanner() { return master_->scanner(); }
  const devicenet::Node& node() { return *scanner().node(mac(kSlaveMac)); }
  std::optional<double> param(unsigned n) { return slave().objects().param_number(n); }
  void set_param(unsigned n, std::vector<std::uint8_t> value) {
    ASSERT_TRUE(slave().objects().set_param_value(n, Bytes(value.data(), value.size())));
  }

  sim::SimWorld world_;
  Recorder events_;
  std::optional<sim::SimEdsSlave> slave_;
  std::optional<sim::SimMaster> master_;
};

TEST_F(EdsSlaveOnTheBus, TheMasterBringsItOnlineAndPollsTheInputAssembly) {
  start();
  ASSERT_TRUE(run_until_online()) << events_.last_reason;
  EXPECT_EQ(node().identity().product_name, "Example IO block 8DI/8DO/1AI");  // fragmented
  EXPECT_EQ(node().identity().serial_number, 0x0A0B0C0Du);
  EXPECT_EQ(slave().owner(), kMasterMac);
  EXPECT_EQ(slave().explicit_state(), sim::ConnectionState::kEstablished);
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kEstablished);
  // The paths the master asked for, the sizes they pack to, the EPR it set.
  const sim::Connection& poll = slave().connections().poll_connection();
  EXPECT_EQ(poll.produced_assembly, kInputs);
  EXPECT_EQ(poll.consumed_assembly, kOutputs);
  EXPECT_EQ(poll.expected_packet_rate_ms, 400);
  EXPECT_EQ(slave().counters().requests_refused, 1u);  // Identity.State: not in the EDS

  // DI 0xA5, status 1, AI -2 mV (0xFFFE): [A5][01][FE FF].
  set_param(3, {0xA5});
  set_param(5, {0x01});
  set_param(2, {0xFE, 0xFF});
  world_.run_for(milliseconds(250));
  EXPECT_EQ(events_.last_response, (std::vector<std::uint8_t>{0xA5, 0x01, 0xFE, 0xFF}));
  EXPECT_EQ(events_.last_response, slave().objects().assembly_data(kInputs));
  set_param(3, {0x0F});
  world_.run_for(milliseconds(150));
  EXPECT_EQ(events_.last_response, (std::vector<std::uint8_t>{0x0F, 0x01, 0xFE, 0xFF}));

  // Outputs: DO 0x3C and the pad byte reach Param4 through Assembly 150.
  const std::array<std::uint8_t, 2> outputs{0x3C, 0x00};
  ASSERT_TRUE(scanner().set_outputs(mac(kSlaveMac), Bytes(outputs), world_.now()).ok());
  world_.run_for(milliseconds(150));
  EXPECT_EQ(param(4), 0x3C);
  EXPECT_EQ(slave().objects().assembly_data(kOutputs), (std::vector<std::uint8_t>{0x3C, 0x00}));
  EXPECT_GT(slave().counters().polls_applied, 0u);  // idle polls until the first outputs

  // Stays online: the keep-alives and polls keep both watchdogs fed.
  world_.run_for(seconds(5));
  EXPECT_EQ(events_.state, NodeState::kOnline);
  EXPECT_EQ(node().counters().timeouts, 0u);
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kEstablished);
}

TEST_F(EdsSlaveOnTheBus, AnIdlePollTakesTheOutputsToZeroUnlessConfiguredToHold) {
  start();
  ASSERT_TRUE(run_until_online()) << events_.last_reason;
  const std::array<std::uint8_t, 2> outputs{0x81, 0x00};
  ASSERT_TRUE(scanner().set_outputs(mac(kSlaveMac), Bytes(outputs), world_.now()).ok());
  world_.run_for(milliseconds(150));
  ASSERT_EQ(param(4), 0x81);
  ASSERT_TRUE(scanner().set_idle(mac(kSlaveMac), true, world_.now()).ok());
  world_.run_for(milliseconds(150));
  EXPECT_EQ(param(4), 0);
  EXPECT_GT(slave().counters().polls_idle, 0u);
  // The idle poll is answered with the inputs all the same.
  EXPECT_EQ(events_.last_response.size(), 4u);
  EXPECT_EQ(events_.state, NodeState::kOnline);
}

TEST_F(EdsSlaveOnTheBus, ADeviceSetToHoldKeepsItsOutputsOnIdle) {
  start();
  set_param(8, {1});  // Output idle action: hold
  ASSERT_TRUE(run_until_online()) << events_.last_reason;
  const std::array<std::uint8_t, 2> outputs{0x81, 0x00};
  ASSERT_TRUE(scanner().set_outputs(mac(kSlaveMac), Bytes(outputs), world_.now()).ok());
  world_.run_for(milliseconds(150));
  ASSERT_TRUE(scanner().set_idle(mac(kSlaveMac), true, world_.now()).ok());
  world_.run_for(milliseconds(150));
  EXPECT_GT(slave().counters().polls_idle, 0u);
  EXPECT_EQ(param(4), 0x81);
}

TEST_F(EdsSlaveOnTheBus, TheOutputsTakeTheIdleAndFaultValuesTheirParametersHold) {
  start();
  set_param(9, {0x42});  // Output idle value
  set_param(7, {0x24});  // Output fault value
  ASSERT_TRUE(run_until_online()) << events_.last_reason;
  const std::array<std::uint8_t, 2> outputs{0x81, 0x00};
  ASSERT_TRUE(scanner().set_outputs(mac(kSlaveMac), Bytes(outputs), world_.now()).ok());
  world_.run_for(milliseconds(150));
  ASSERT_TRUE(scanner().set_idle(mac(kSlaveMac), true, world_.now()).ok());
  world_.run_for(milliseconds(150));
  EXPECT_EQ(param(4), 0x42);
  ASSERT_TRUE(scanner().set_outputs(mac(kSlaveMac), Bytes(outputs), world_.now()).ok());
  world_.run_for(milliseconds(150));
  ASSERT_EQ(param(4), 0x81);
  // The master gone: the poll connection's watchdog is the fault.
  master_.reset();
  world_.run_for(seconds(3));
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kTimedOut);
  EXPECT_EQ(param(4), 0x24);
}

TEST_F(EdsSlaveOnTheBus, WithoutTheSafeStateParametersTheOptionsDecide) {
  profiles::eds::EdsFile file = test::example_eds(test::kIoBlockEds);
  std::erase_if(file.params, [](const profiles::eds::Param& p) { return p.number >= 6; });
  sim::EdsSlaveOptions options;
  options.idle_action = sim::OutputAction::kHold;
  start(options, std::move(file));
  ASSERT_TRUE(run_until_online()) << events_.last_reason;
  const std::array<std::uint8_t, 2> outputs{0x81, 0x00};
  ASSERT_TRUE(scanner().set_outputs(mac(kSlaveMac), Bytes(outputs), world_.now()).ok());
  world_.run_for(milliseconds(150));
  ASSERT_TRUE(scanner().set_idle(mac(kSlaveMac), true, world_.now()).ok());
  world_.run_for(milliseconds(150));
  EXPECT_GT(slave().counters().polls_idle, 0u);
  EXPECT_EQ(param(4), 0x81);
}

TEST_F(EdsSlaveOnTheBus, ReleaseAtShutdownLeavesTheSetUnownedAndTheOutputsIdle) {
  start();
  ASSERT_TRUE(run_until_online()) << events_.last_reason;
  const std::array<std::uint8_t, 2> outputs{0xFF, 0x00};
  ASSERT_TRUE(scanner().set_outputs(mac(kSlaveMac), Bytes(outputs), world_.now()).ok());
  world_.run_for(milliseconds(150));
  ASSERT_EQ(param(4), 0xFF);
  scanner().stop(world_.now());
  ASSERT_TRUE(world_.run_until([&] { return events_.state == NodeState::kStopped; }, seconds(5)));
  EXPECT_EQ(slave().owner(), devicenet::MacId::kNone);
  EXPECT_EQ(slave().explicit_state(), sim::ConnectionState::kNonExistent);
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kNonExistent);
  EXPECT_EQ(param(4), 0);
}

TEST_F(EdsSlaveOnTheBus, ASilentMasterTimesThePollConnectionOutAndTheOutputsFault) {
  start();
  ASSERT_TRUE(run_until_online()) << events_.last_reason;
  const std::array<std::uint8_t, 2> outputs{0x42, 0x00};
  ASSERT_TRUE(scanner().set_outputs(mac(kSlaveMac), Bytes(outputs), world_.now()).ok());
  world_.run_for(milliseconds(150));
  ASSERT_EQ(param(4), 0x42);
  // The master leaves the bus: after 4 x EPR (1600 ms) the poll connection
  // times out (action 0: timed out, the outputs to their fault value); after
  // 4 x the explicit EPR the explicit connection goes too, and with nothing
  // established the set is released (bridge/PROTOCOL.md §7).
  const TimePoint gone = world_.now();
  master_.reset();
  world_.run_until(gone + milliseconds(1450));
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kEstablished);
  EXPECT_EQ(param(4), 0x42);
  world_.run_until(gone + milliseconds(1700));
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kTimedOut);
  EXPECT_EQ(param(4), 0);
  world_.run_until(gone + seconds(11));
  EXPECT_EQ(slave().explicit_state(), sim::ConnectionState::kNonExistent);
  EXPECT_EQ(slave().owner(), devicenet::MacId::kNone);
  EXPECT_EQ(slave().connections().watchdog_timeouts(), 2u);
}

}  // namespace
}  // namespace dnbridge::test
