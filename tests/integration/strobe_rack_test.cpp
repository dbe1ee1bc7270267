// Devices on a bit-strobe connection (profile "eds", connection =
// "bit-strobe") in a rack, against the simulated device driven by the same
// EDS (the example valve manifold): the master allocates instance 3 beside
// the poll connection and sets it up from what the device has; one
// bit-strobe command per period serves every strobed node of the port, and
// each answers with its inputs; nothing is acknowledged; 4 x EPR without a
// response takes the node through loss handling, and it comes back when the
// device is heard again.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "bridge/devicenet/wire/identifier.hpp"
#include "bridge/rack/device_rack.hpp"
#include "rack_fixture.hpp"
#include "support/example_eds.hpp"

namespace dnbridge::test {
namespace {

using ByteVec = std::vector<std::uint8_t>;
using devicenet::Group1Message;
using devicenet::Group2Message;

constexpr unsigned kValves = 22;
constexpr unsigned kValves2 = 23;

// The example valve manifold at `m`, strobed at its poll period of 100 ms,
// EPR 400 ms.
rack::DeviceConfig strobed_manifold(unsigned m, Duration poll = milliseconds(100)) {
  rack::DeviceConfig d;
  d.node.mac = mac(m);
  d.node.name = "valves";
  d.node.poll_period = poll;
  d.node.expected_packet_rate = milliseconds(400);
  d.eds = std::make_shared<const profiles::eds::EdsFile>(example_eds(kValveManifoldEds));
  d.eds_path = kValveManifoldEds;
  d.settings.connection = profiles::eds::ConnectionKind::kStrobe;
  d.settings.safe_state = {{"Output fault action", 0},
                           {"Output fault value", 0x0001},
                           {"Output idle action", 0},
                           {"Output idle value", 0x0080}};
  return d;
}

class StrobeRackTest : public ::testing::Test {
 protected:
  void start(std::vector<rack::DeviceConfig> devices = {strobed_manifold(kValves)}) {
    auto config = rack_config({});
    config.devices = std::move(devices);
    rack_.emplace(config);
    rack_->start();
    // Every bit-strobe command the master sends.
    world().bus().set_tap([this](const sim::WireFrame& w) {
      if (w.frame.id == strobe_id())
        strobes_.push_back(ByteVec(w.frame.payload().begin(), w.frame.payload().end()));
    });
  }
  bool run_until_online() {
    return world().run_until([&] { return rack_->all_online(); }, seconds(20));
  }
  sim::SimWorld& world() { return rack_->world(); }
  const rack::DeviceView& view(unsigned m = kValves) { return *rack_->devices().device(mac(m)); }
  sim::EdsSlave& device(unsigned m = kValves) { return rack_->eds_device(mac(m)).device(); }
  const devicenet::Node& node(unsigned m = kValves) { return *rack_->scanner().node(mac(m)); }
  const devicenet::NodeCounters& counters(unsigned m = kValves) { return node(m).counters(); }
  TimePoint now() { return rack_->now(); }
  std::uint32_t strobe_id() {
    return devicenet::group2_id(rack_->scanner().config().master_mac,
                                Group2Message::kMasterBitStrobeCommand);
  }
  std::uint32_t response_id(unsigned m = kValves) {
    return devicenet::group1_id(Group1Message::kSlaveBitStrobeResponse, mac(m));
  }

  std::optional<sim::SimRack> rack_;
  std::vector<ByteVec> strobes_;
};

TEST_F(StrobeRackTest, TheNodeIsStrobedEveryPeriodAndAnswersWithItsStatus) {
  start();
  ASSERT_TRUE(run_until_online()) << node().reason();
  EXPECT_EQ(device().strobe_state(), sim::ConnectionState::kEstablished);
  EXPECT_EQ(device().connections().strobe_connection().allocated_as,
            devicenet::allocation::kBitStrobe);
  // Its produced path as the profile set it: the status assembly (102),
  // which the poll connection answers with too.
  EXPECT_EQ(device().connections().strobe_connection().produced_assembly, 102u);
  EXPECT_EQ(device().connections().poll_connection().produced_assembly, 102u);
  EXPECT_EQ(device().connections().strobe_connection().expected_packet_rate_ms, 400u);
  ASSERT_TRUE(node().cos_settings().has_value());
  EXPECT_TRUE(node().cos_settings()->ack_suppressed);
  EXPECT_NE(node().reason().find("bit-strobed (EPR 400 ms"), std::string::npos) << node().reason();

  strobes_.clear();
  const auto before = counters();
  const auto device_before = device().strobe_counters();
  world().run_for(milliseconds(1000));
  // One command every 100 ms, eight bytes, every bit 0; each answered.
  EXPECT_GE(strobes_.size(), 9u);
  EXPECT_LE(strobes_.size(), 11u);
  for (const auto& s : strobes_) EXPECT_EQ(s, ByteVec(8, 0));
  EXPECT_EQ(device().strobe_counters().commands - device_before.commands, strobes_.size());
  EXPECT_EQ(device().strobe_counters().responses - device_before.responses, strobes_.size());
  EXPECT_FALSE(device().strobe_counters().last_bit);
  EXPECT_EQ(counters().cos_messages - before.cos_messages, strobes_.size());
  EXPECT_EQ(counters().cos_acks, 0u);
  EXPECT_EQ(counters().cos_errors, 0u);
  EXPECT_EQ(rack_->scanner().counters().bit_strobes, counters().cos_messages);

  // The manifold's status (Assembly 102: supply ok, coil short circuit, as
  // its Discrete Input Points have them) changes: the next strobe tells it,
  // while its poll responses are lost on the bus.
  ASSERT_TRUE(view().has_inputs);
  EXPECT_EQ(view().inputs, ByteVec{0x00});
  const auto no_polls = world().bus().faults().add(
      sim::FaultRule::drop(devicenet::group1_id(Group1Message::kSlavePollResponse, mac(kValves))));
  const std::uint64_t poll_responses = counters().responses;
  ASSERT_TRUE(device().objects().set_assembly_data(102, Bytes(ByteVec{0x01})));
  const std::uint64_t responses = counters().cos_messages;
  world().run_for(milliseconds(110));
  EXPECT_EQ(counters().cos_messages, responses + 1);
  EXPECT_EQ(view().inputs, ByteVec{0x01});
  ASSERT_TRUE(device().objects().set_assembly_data(102, Bytes(ByteVec{0x03})));
  world().run_for(milliseconds(110));
  EXPECT_EQ(view().inputs, ByteVec{0x03});
  EXPECT_EQ(counters().responses, poll_responses);
  world().bus().faults().remove(no_polls);
  EXPECT_EQ(node().state(), devicenet::NodeState::kOnline) << node().reason();

  // The coils stay on the poll connection.
  ASSERT_TRUE(
      rack_->devices().command(mac(kValves), ByteVec{0x42, 0x01}, "supervisor", now()).ok());
  // (by the next poll slot: the poll outstanding lost its response).
  world().run_for(milliseconds(150));
  EXPECT_EQ(*device().objects().param_number(4), 0x0142);
}

TEST_F(StrobeRackTest, OneCommandServesEveryStrobedNodeAtTheShortestPollPeriod) {
  start({strobed_manifold(kValves, milliseconds(100)),
         strobed_manifold(kValves2, milliseconds(250))});
  ASSERT_TRUE(run_until_online()) << node().reason() << " / " << node(kValves2).reason();
  strobes_.clear();
  const auto a = counters(kValves).cos_messages;
  const auto b = counters(kValves2).cos_messages;
  world().run_for(milliseconds(1000));
  EXPECT_GE(strobes_.size(), 9u);
  EXPECT_LE(strobes_.size(), 11u);
  // Both answer each one.
  EXPECT_EQ(counters(kValves).cos_messages - a, strobes_.size());
  EXPECT_EQ(counters(kValves2).cos_messages - b, strobes_.size());
}

TEST_F(StrobeRackTest, ANodeAddedWithAShorterPeriodIsStrobedAtItsPeriodAtOnce) {
  // Strobed every 10 s, then a node polled every 20 ms comes in (a reload).
  auto slow = strobed_manifold(kValves, milliseconds(10000));
  slow.node.expected_packet_rate = milliseconds(10000);
  start({slow});
  ASSERT_TRUE(run_until_online()) << node().reason();
  world().run_for(milliseconds(300));
  auto fast = strobed_manifold(kValves2, milliseconds(20));
  fast.node.expected_packet_rate = milliseconds(80);
  const auto eds = std::make_shared<const profiles::eds::EdsFile>(example_eds(kValveManifoldEds));
  rack_->add_eds_device(*eds, sim::default_eds_slave_options(mac(kValves2)), now());
  rack_->port().reconfigure(rack_->scanner().config(),
                            rack::PortNodes(std::vector<rack::DeviceConfig>{slow, fast}), now());
  ASSERT_TRUE(world().run_until(
      [&] { return node(kValves2).state() == devicenet::NodeState::kOnline; }, seconds(5)))
      << node(kValves2).reason();
  strobes_.clear();
  world().run_for(milliseconds(1000));
  // Every 20 ms from then on; never lost (4 x 80 ms without a response).
  EXPECT_GE(strobes_.size(), 49u);
  EXPECT_LE(strobes_.size(), 51u);
  EXPECT_EQ(counters(kValves2).heartbeats_missed, 0u);
  EXPECT_EQ(counters(kValves2).reconnects, 0u);
  EXPECT_EQ(node(kValves2).state(), devicenet::NodeState::kOnline);
}

TEST_F(StrobeRackTest, ANodeThatStillAnswersTheStrobesAfterItsReleaseWasLostIsReleased) {
  start({strobed_manifold(kValves), strobed_manifold(kValves2)});
  ASSERT_TRUE(run_until_online()) << node().reason() << " / " << node(kValves2).reason();
  // Taken out of the scan list; its idle poll and Release are lost. The
  // strobes for the other node keep its bit-strobe connection alive.
  const std::uint32_t unconnected =
      devicenet::group2_id(mac(kValves2), Group2Message::kUnconnectedExplicitRequest);
  const auto lost = world().bus().faults().add(sim::FaultRule::drop(unconnected));
  rack_->port().reconfigure(
      rack_->scanner().config(),
      rack::PortNodes(std::vector<rack::DeviceConfig>{strobed_manifold(kValves)}), now());
  ASSERT_TRUE(world().run_until([&] { return rack_->scanner().nodes_leaving() == 0; }, seconds(5)));
  world().bus().faults().remove(lost);
  ASSERT_EQ(device(kValves2).strobe_state(), sim::ConnectionState::kEstablished);
  // Its next response: the master releases its bit-strobe connection.
  world().run_for(milliseconds(300));
  EXPECT_EQ(device(kValves2).strobe_state(), sim::ConnectionState::kNonExistent);
  const auto answered = device(kValves2).strobe_counters().responses;
  world().run_for(milliseconds(500));
  EXPECT_EQ(device(kValves2).strobe_counters().responses, answered);
  // It is no other master's: a bus scan asks it.
  EXPECT_TRUE(rack_->scanner().unconfigured_heard(now()).test(kValves2));
  EXPECT_EQ(node().state(), devicenet::NodeState::kOnline);
}

TEST_F(StrobeRackTest, ABitStrobeConnectionLeftFromBeforeIsReleasedAtAllocation) {
  start();
  ASSERT_TRUE(run_until_online()) << node().reason();
  // The master loses the bus and checks its MAC again: the device keeps
  // its connections, which the master allocates afresh.
  std::vector<std::uint8_t> releases;
  const std::uint32_t unconnected =
      devicenet::group2_id(mac(kValves), Group2Message::kUnconnectedExplicitRequest);
  world().bus().set_tap([&](const sim::WireFrame& w) {
    if (w.frame.id == unconnected && w.frame.len == 5 && w.frame.data[1] == 0x4C) {
      releases.push_back(w.frame.data[4]);
    }
  });
  rack_->scanner().recheck_mac("bus-off recovered", now());
  ASSERT_TRUE(world().run_until(
      [&] { return rack_->scanner().state() != devicenet::PortState::kRunning; }, seconds(1)));
  ASSERT_TRUE(run_until_online()) << node().reason();
  // The explicit connection, which the device still has, released when its
  // Allocate is refused; then its I/O connections still allocated from
  // before (poll and bit-strobe), together, before the configuration.
  EXPECT_EQ(releases, (std::vector<std::uint8_t>{0x01, 0x06}));
  EXPECT_EQ(device().strobe_state(), sim::ConnectionState::kEstablished);
}

TEST_F(StrobeRackTest, FourEprsWithoutAResponseLoseTheNodeAndItComesBackWhenHeardAgain) {
  start();
  ASSERT_TRUE(run_until_online()) << node().reason();
  ASSERT_TRUE(
      rack_->devices().command(mac(kValves), ByteVec{0x42, 0x00}, "supervisor", now()).ok());
  world().run_for(milliseconds(300));
  ASSERT_EQ(*device().objects().param_number(4), 0x42);
  // The device's responses no longer reach the master; its polls still do.
  const auto rule = world().bus().faults().add(sim::FaultRule::drop(response_id()));
  const TimePoint cut = now();
  ASSERT_TRUE(world().run_until([&] { return node().state() != devicenet::NodeState::kOnline; },
                                seconds(3)));
  // 4 x EPR of 400 ms after the last response, which came within one strobe
  // period before the cut.
  EXPECT_GE(now() - cut, milliseconds(1500));
  EXPECT_LE(now() - cut, milliseconds(1600));
  EXPECT_EQ(counters().heartbeats_missed, 1u);
  EXPECT_EQ(node().last_error().kind, devicenet::NodeError::Kind::kStrobeMissed);
  EXPECT_NE(node().reason().find("no bit-strobe response for 1600 ms (4 x EPR of 400 ms)"),
            std::string::npos)
      << node().reason();
  // The poll connection lived: the coils went to the idle value (0x0080) at
  // once, and what the device held was released.
  world().run_for(milliseconds(20));
  EXPECT_EQ(*device().objects().param_number(4), 0x80);
  EXPECT_EQ(device().owner(), devicenet::MacId::kNone);
  EXPECT_EQ(device().strobe_state(), sim::ConnectionState::kNonExistent);

  // No node strobed: no command on the bus until it is allocated again
  // (after at least 3/4 of 250 ms, the first retry with its jitter).
  strobes_.clear();
  world().run_for(milliseconds(150));
  EXPECT_TRUE(strobes_.empty());

  // Heard again: allocated afresh, online, strobed.
  world().bus().faults().remove(rule);
  ASSERT_TRUE(run_until_online()) << node().reason();
  const std::uint64_t responses = counters().cos_messages;
  world().run_for(milliseconds(500));
  EXPECT_GT(counters().cos_messages, responses);
  EXPECT_EQ(counters().heartbeats_missed, 1u);
  EXPECT_EQ(counters().reconnects, 1u);
}

TEST_F(StrobeRackTest, ResponsesOfTheWrongSizeAreNotTakenAndTheLossSaysWhy) {
  start();
  ASSERT_TRUE(run_until_online()) << node().reason();
  world().run_for(milliseconds(300));
  const auto before = counters();
  // Every response from now on arrives a byte short: empty.
  world().bus().faults().add(sim::FaultRule::corrupt(response_id(), sim::Corruption::kTruncate, 1));
  ASSERT_TRUE(world().run_until([&] { return node().state() != devicenet::NodeState::kOnline; },
                                seconds(3)));
  EXPECT_EQ(counters().cos_messages, before.cos_messages);
  EXPECT_GT(counters().cos_errors, before.cos_errors);
  EXPECT_NE(node().reason().find("bit-strobe response of 0 bytes, expected 1"), std::string::npos)
      << node().reason();
}

TEST_F(StrobeRackTest, AtShutdownTheCoilsGoIdleAndTheStrobesStop) {
  start();
  ASSERT_TRUE(run_until_online()) << node().reason();
  ASSERT_TRUE(
      rack_->devices().command(mac(kValves), ByteVec{0x42, 0x00}, "supervisor", now()).ok());
  world().run_for(milliseconds(300));
  rack_->scanner().stop(now());
  ASSERT_TRUE(world().run_until([&] { return rack_->scanner().stopped(); }, seconds(5)));
  EXPECT_EQ(*device().objects().param_number(4), 0x80);
  EXPECT_EQ(device().owner(), devicenet::MacId::kNone);
  strobes_.clear();
  world().run_for(milliseconds(500));
  EXPECT_TRUE(strobes_.empty());
}

}  // namespace
}  // namespace dnbridge::test
