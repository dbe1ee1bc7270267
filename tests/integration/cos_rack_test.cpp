// A device on a change-of-state or cyclic connection (profile "eds",
// connection = "change-of-state" or "cyclic") in a rack, against the
// simulated device driven by the same EDS: the master allocates instance 4
// beside the poll connection and sets it up from what the device has; the
// inputs come as the device produces them, sooner than the next poll; each
// message is acknowledged (or, suppressed, none), an acknowledgment lost on
// the bus makes the device send the message again and the master counts it;
// 4 x EPR without a message takes the node through loss handling, and it
// comes back when the device is heard again.
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

constexpr unsigned kIo = 21;
constexpr unsigned kDigitalInputs = 3;  // the example I/O block's Param3

// The example I/O block at MAC 21 on change of state: polled once a second
// (its outputs), a heartbeat every 200 ms, changes no closer than 10 ms.
rack::DeviceConfig cos_block(
    profiles::eds::ConnectionKind kind = profiles::eds::ConnectionKind::kChangeOfState) {
  rack::DeviceConfig d;
  d.node.mac = mac(kIo);
  d.node.name = "cos block";
  d.node.poll_period = milliseconds(1000);
  d.node.expected_packet_rate = milliseconds(1000);
  d.eds = std::make_shared<const profiles::eds::EdsFile>(example_eds(kIoBlockEds));
  d.eds_path = kIoBlockEds;
  d.settings.connection = kind;
  d.settings.heartbeat = milliseconds(200);
  if (kind != profiles::eds::ConnectionKind::kCyclic) d.settings.inhibit = milliseconds(10);
  d.settings.safe_state = {{"Output fault action", 0},
                           {"Output fault value", 0x01},
                           {"Output idle action", 0},
                           {"Output idle value", 0x80}};
  return d;
}

class CosRackTest : public ::testing::Test {
 protected:
  void start(rack::DeviceConfig device = cos_block()) {
    auto config = rack_config({});
    config.devices = {std::move(device)};
    rack_.emplace(config);
    rack_->start();
  }
  bool run_until_online() {
    return world().run_until([&] { return rack_->all_online(); }, seconds(20));
  }
  sim::SimWorld& world() { return rack_->world(); }
  const rack::DeviceView& view() { return *rack_->devices().device(mac(kIo)); }
  sim::EdsSlave& device() { return rack_->eds_device(mac(kIo)).device(); }
  const devicenet::Node& node() { return *rack_->scanner().node(mac(kIo)); }
  const devicenet::NodeCounters& counters() { return node().counters(); }
  TimePoint now() { return rack_->now(); }
  // The device's digital inputs change.
  void set_inputs(std::uint8_t di) {
    ASSERT_TRUE(device().objects().set_param_value(kDigitalInputs, Bytes(ByteVec{di})));
    device().inputs_changed(now());
  }
  std::uint32_t ack_id() {
    return devicenet::group2_id(mac(kIo), Group2Message::kMasterCosCyclicAck);
  }
  std::uint32_t cos_id() { return devicenet::group1_id(Group1Message::kSlaveCosCyclic, mac(kIo)); }

  std::optional<sim::SimRack> rack_;
};

TEST_F(CosRackTest, AChangeReachesTheViewBeforeTheNextPollAndEveryMessageIsAcknowledged) {
  start();
  ASSERT_TRUE(run_until_online()) << node().reason();
  EXPECT_EQ(device().cos_state(), sim::ConnectionState::kEstablished);
  EXPECT_TRUE(device().cos_producing());
  EXPECT_EQ(device().connections().cos_connection().allocated_as,
            devicenet::allocation::kChangeOfState);
  EXPECT_EQ(device().connections().cos_connection().inhibit_ms, 10u);
  ASSERT_TRUE(node().cos_settings().has_value());
  EXPECT_EQ(node().cos_settings()->expected_packet_rate, milliseconds(200));
  EXPECT_EQ(node().cos_settings()->ack_timer, milliseconds(20));
  EXPECT_EQ(node().cos_settings()->retry_limit, 1u);
  EXPECT_NE(node().reason().find("on change of state (EPR 200 ms, acknowledged"), std::string::npos)
      << node().reason();

  // Right after a poll's answer: the next poll is a second away.
  ASSERT_TRUE(world().run_until([&] { return counters().responses >= 2; }, seconds(3)));
  const auto before = counters();
  set_inputs(0x5A);
  world().run_for(milliseconds(5));
  // In the view by the change-of-state message alone.
  EXPECT_EQ(counters().polls, before.polls);
  EXPECT_EQ(counters().responses, before.responses);
  EXPECT_EQ(counters().cos_messages, before.cos_messages + 1);
  ASSERT_TRUE(view().has_inputs);
  EXPECT_EQ(view().inputs[0], 0x5A);

  // Heartbeats every 200 ms, each acknowledged, none sent again.
  world().run_for(milliseconds(1000));
  EXPECT_GE(counters().cos_messages, 6u);
  EXPECT_EQ(counters().cos_acks, counters().cos_messages);
  EXPECT_EQ(counters().cos_retries, 0u);
  EXPECT_EQ(device().cos_counters().retries, 0u);
  EXPECT_EQ(device().cos_counters().acks_received, device().cos_counters().produced);
  EXPECT_EQ(counters().heartbeats_missed, 0u);

  // The outputs stay on the poll connection.
  ASSERT_TRUE(rack_->devices().command(mac(kIo), ByteVec{0x42, 0x00}, "supervisor", now()).ok());
  world().run_for(milliseconds(50));
  EXPECT_EQ(*device().objects().param_number(4), 0x42);
}

TEST_F(CosRackTest, AnAcknowledgmentLostOnTheBusIsRetriedByTheDeviceAndCountedByTheMaster) {
  start();
  ASSERT_TRUE(run_until_online()) << node().reason();
  world().run_for(milliseconds(300));
  const auto before = counters();
  ASSERT_EQ(before.cos_retries, 0u);

  // The next two acknowledgments are lost: the change is sent again after
  // the device's acknowledge timer (20 ms), once (its retry limit).
  world().bus().faults().add(
      sim::FaultRule{ack_id(), 0x7FF, std::nullopt, sim::FaultAction::kDrop, 1.0, 2});
  set_inputs(0x11);
  world().run_for(milliseconds(60));
  EXPECT_EQ(device().cos_counters().retries, 1u);
  EXPECT_EQ(counters().cos_retries - before.cos_retries, 1u);
  EXPECT_EQ(counters().cos_messages - before.cos_messages, 2u);
  EXPECT_EQ(counters().cos_acks - before.cos_acks, 2u);
  EXPECT_EQ(view().inputs[0], 0x11);
  EXPECT_EQ(node().state(), devicenet::NodeState::kOnline);

  // Acknowledged again: nothing more is retried.
  set_inputs(0x22);
  world().run_for(milliseconds(500));
  EXPECT_EQ(device().cos_counters().retries, 1u);
  EXPECT_EQ(counters().cos_retries - before.cos_retries, 1u);
  EXPECT_EQ(view().inputs[0], 0x22);
}

TEST_F(CosRackTest, WithAcknowledgmentSuppressedNothingIsAcknowledgedOrRetried) {
  auto d = cos_block();
  d.settings.acknowledged = false;
  start(d);
  ASSERT_TRUE(run_until_online()) << node().reason();
  EXPECT_EQ(device().connections().cos_connection().allocated_as,
            devicenet::allocation::kChangeOfState | devicenet::allocation::kAckSuppression);
  set_inputs(0x33);
  world().run_for(milliseconds(500));
  EXPECT_EQ(view().inputs[0], 0x33);
  EXPECT_GE(counters().cos_messages, 3u);
  EXPECT_EQ(counters().cos_acks, 0u);
  EXPECT_EQ(device().cos_counters().retries, 0u);
}

TEST_F(CosRackTest, FourHeartbeatsMissedLoseTheNodeAndItComesBackWhenHeardAgain) {
  start();
  ASSERT_TRUE(run_until_online()) << node().reason();
  // Commanded: the outputs 0x42.
  ASSERT_TRUE(rack_->devices().command(mac(kIo), ByteVec{0x42, 0x00}, "supervisor", now()).ok());
  world().run_for(milliseconds(300));
  ASSERT_EQ(*device().objects().param_number(4), 0x42);
  // The device's messages no longer reach the master; its polls still do.
  const auto rule = world().bus().faults().add(sim::FaultRule::drop(cos_id()));
  const TimePoint cut = now();
  ASSERT_TRUE(world().run_until([&] { return node().state() != devicenet::NodeState::kOnline; },
                                seconds(2)));
  // 4 x EPR of 200 ms after the last message, which came within one EPR
  // before the cut.
  EXPECT_GE(now() - cut, milliseconds(600));
  EXPECT_LE(now() - cut, milliseconds(800));
  EXPECT_EQ(counters().heartbeats_missed, 1u);
  EXPECT_EQ(node().last_error().kind, devicenet::NodeError::Kind::kHeartbeatMissed);
  EXPECT_NE(node().reason().find("no change-of-state message for 800 ms (4 x EPR of 200 ms)"),
            std::string::npos)
      << node().reason();
  // The poll connection lived: the outputs went to the device's idle value
  // (0x80) at once, not after its own watchdog (4 x 1000 ms), and what it
  // held was released.
  world().run_for(milliseconds(20));
  EXPECT_EQ(*device().objects().param_number(4), 0x80);
  EXPECT_EQ(device().owner(), devicenet::MacId::kNone);
  // The Release's answer is no news: the loss stays the last error.
  EXPECT_EQ(node().last_error().kind, devicenet::NodeError::Kind::kHeartbeatMissed);

  // Heard again: allocated afresh, online, producing.
  world().bus().faults().remove(rule);
  ASSERT_TRUE(run_until_online()) << node().reason();
  const std::uint64_t messages = counters().cos_messages;
  world().run_for(milliseconds(500));
  EXPECT_GT(counters().cos_messages, messages);
  EXPECT_EQ(counters().heartbeats_missed, 1u);
  EXPECT_EQ(counters().reconnects, 1u);
}

TEST_F(CosRackTest, MessagesOfTheWrongSizeAreNeitherTakenNorAcknowledgedAndTheLossSaysWhy) {
  start();
  ASSERT_TRUE(run_until_online()) << node().reason();
  world().run_for(milliseconds(300));
  const auto before = counters();
  // Every message from now on arrives a byte short.
  world().bus().faults().add(sim::FaultRule::corrupt(cos_id(), sim::Corruption::kTruncate, 1));
  ASSERT_TRUE(world().run_until([&] { return node().state() != devicenet::NodeState::kOnline; },
                                seconds(2)));
  EXPECT_EQ(counters().cos_messages, before.cos_messages);
  EXPECT_EQ(counters().cos_acks, before.cos_acks);
  EXPECT_GT(counters().cos_errors, before.cos_errors);
  EXPECT_EQ(counters().heartbeats_missed, 1u);
  EXPECT_NE(node().reason().find("were refused: change-of-state message of 3 bytes, expected 4"),
            std::string::npos)
      << node().reason();
}

TEST_F(CosRackTest, ALostAnswerToTheAllocateOfConnection4IsNotAFault) {
  start();
  // The master's Allocate of instance 4 on the wire: the device's answer to
  // it is lost. The master asks again, is told "already allocated" (0x0B),
  // releases the connection and allocates it once more.
  const std::uint32_t unconnected =
      devicenet::group2_id(mac(kIo), Group2Message::kUnconnectedExplicitRequest);
  bool armed = false;
  world().bus().set_tap([&](const sim::WireFrame& w) {
    if (armed || w.frame.id != unconnected || w.frame.len != 6 || w.frame.data[1] != 0x4B ||
        w.frame.data[4] != devicenet::allocation::kChangeOfState) {
      return;
    }
    armed = true;
    world().bus().faults().add(
        sim::FaultRule{devicenet::group2_id(mac(kIo), Group2Message::kSlaveExplicitResponse), 0x7FF,
                       std::nullopt, sim::FaultAction::kDrop, 1.0, 1});
  });
  ASSERT_TRUE(run_until_online()) << node().reason();
  world().bus().set_tap({});
  ASSERT_TRUE(armed);
  EXPECT_EQ(world().bus().stats().fault_dropped, 1u);
  EXPECT_EQ(counters().allocate_attempts, 1u);
  EXPECT_EQ(node().explicit_counters().timeouts, 1u);
  // Identity.State's 0x14 (the example has none), then the 0x0B.
  EXPECT_EQ(node().explicit_counters().device_errors, 2u);
  EXPECT_EQ(node().last_error().general_status, cip::GeneralStatus::kAlreadyInRequestedMode);
  EXPECT_EQ(device().cos_state(), sim::ConnectionState::kEstablished);
  world().run_for(milliseconds(500));
  EXPECT_GT(counters().cos_messages, 0u);
}

TEST_F(CosRackTest, IdlePollsAnsweredEmptyLeaveTheInputsOfTheChangeOfStateConnection) {
  // A device that answers an idle poll with no data: the inputs stay those
  // its change-of-state messages carry, not withheld at every poll.
  auto config = rack_config({});
  auto d = cos_block();
  d.node.poll_period = milliseconds(100);
  config.devices = {d};
  config.create_devices = false;
  rack_.emplace(config);
  auto options = sim::default_eds_slave_options(mac(kIo));
  options.idle_poll_answered_empty = true;
  rack_->add_eds_device(example_eds(kIoBlockEds), options, std::nullopt);
  rack_->start();
  ASSERT_TRUE(run_until_online()) << node().reason();
  set_inputs(0x66);
  world().run_for(milliseconds(50));
  ASSERT_TRUE(view().has_inputs);
  const auto status_changes = view().status_changes;
  const auto before = counters();
  world().run_for(milliseconds(1000));
  EXPECT_GE(counters().idle_empty_responses - before.idle_empty_responses, 9u);
  EXPECT_TRUE(view().has_inputs);
  EXPECT_EQ(view().inputs[0], 0x66);
  EXPECT_EQ(view().status_changes, status_changes);
}

TEST_F(CosRackTest, ACyclicDeviceProducesEveryCycleAndAChangeWaitsForIt) {
  start(cos_block(profiles::eds::ConnectionKind::kCyclic));
  ASSERT_TRUE(run_until_online()) << node().reason();
  EXPECT_EQ(device().connections().cos_connection().allocated_as, devicenet::allocation::kCyclic);
  world().run_for(milliseconds(100));
  const std::uint64_t messages = counters().cos_messages;
  set_inputs(0x44);
  world().run_for(milliseconds(1000));
  // One message per 200 ms cycle, the change among them.
  EXPECT_EQ(counters().cos_messages - messages, 5u);
  EXPECT_EQ(view().inputs[0], 0x44);
  EXPECT_EQ(counters().cos_acks, counters().cos_messages);
}

}  // namespace
}  // namespace dnbridge::test
