// What a node that cannot be brought online costs the bus, and what the
// master does when the bus itself comes back: every retry path backs off
// (allocation, release after "already allocated", a node that allocates and
// then goes silent, another master's node), the other nodes keep their poll
// period meanwhile, and after the bus was lost the master checks its own MAC
// again before it scans. Also the serial number pinned per node. Master and
// simulated devices on the in-process bus, fake clock.
#include <gtest/gtest.h>

#include <map>
#include <optional>
#include <string>

#include "bridge/cip/general_status.hpp"
#include "bridge/devicenet/wire/identifier.hpp"
#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

using cip::GeneralStatus;

constexpr unsigned kGood = 5;    // a CDN127 that comes online
constexpr unsigned kBroken = 9;  // a node that never does

// A node that answers every unconnected request (Allocate, Release) with
// one CIP error, or accepts Allocate and then never answers again, or is
// silent: the broken nodes a master meets.
class BrokenNode final : public sim::SimEndpoint {
 public:
  enum class Behaviour { kRefuse, kAllocateThenSilent, kSilent };
  BrokenNode(sim::SimWorld& world, MacId mac, Behaviour behaviour, GeneralStatus status = {},
             std::uint8_t additional = 0xFF)
      : world_(world),
        handle_(world.bus().attach(*this)),
        mac_(mac),
        behaviour_(behaviour),
        status_(status),
        additional_(additional) {
    world_.add(*this);
  }
  ~BrokenNode() override {
    world_.remove(*this);
    (void)world_.bus().detach(handle_);
  }

  void on_frame(const can::CanFrame& frame, TimePoint now) override {
    if (frame.id !=
            devicenet::group2_id(mac_, devicenet::Group2Message::kUnconnectedExplicitRequest) ||
        frame.len < 2) {
      return;
    }
    const std::uint8_t header = frame.data[0] & 0x7F;  // XID and the master's MAC
    const std::uint8_t service = frame.data[1];
    can::CanFrame answer;
    answer.id = devicenet::group2_id(mac_, devicenet::Group2Message::kSlaveExplicitResponse);
    if (behaviour_ == Behaviour::kSilent) return;
    if (behaviour_ == Behaviour::kAllocateThenSilent && service == 0x4B) {
      answer.len = 3;  // [hdr][CB][body format 8/8]
      answer.data[0] = header;
      answer.data[1] = 0xCB;
      answer.data[2] = 0x00;
    } else if (behaviour_ == Behaviour::kRefuse) {
      answer.len = 4;  // [hdr][94 error response][general][additional]
      answer.data[0] = header;
      answer.data[1] = 0x94;
      answer.data[2] = static_cast<std::uint8_t>(status_);
      answer.data[3] = additional_;
    } else {
      return;
    }
    world_.bus().send(handle_, answer, now);
  }
  TimePoint next_deadline() const override { return kNever; }
  void on_timer(TimePoint) override {}

 private:
  sim::SimWorld& world_;
  sim::NodeHandle handle_;
  MacId mac_;
  Behaviour behaviour_;
  GeneralStatus status_;
  std::uint8_t additional_;
};

// Frames on the wire to or from `mac` (Group 2, which carries the node's
// MAC in every message the master and a Group 2 slave exchange).
class FrameCounter {
 public:
  explicit FrameCounter(sim::SimWorld& world) {
    world.bus().set_tap([this](const sim::WireFrame& f) {
      if (auto id = devicenet::decode_identifier(f.frame.id); id) ++by_mac_[id->mac.value()];
    });
  }
  std::uint64_t of(unsigned mac) const {
    auto it = by_mac_.find(mac);
    return it == by_mac_.end() ? 0 : it->second;
  }

 private:
  std::map<unsigned, std::uint64_t> by_mac_;
};

class StartupBackoff : public ::testing::Test {
 protected:
  void build(BrokenNode::Behaviour behaviour, GeneralStatus status = {},
             std::uint8_t additional = 0xFF) {
    auto config = rack_config({kGood, kBroken});
    config.create_devices = false;
    rack_ = std::make_unique<sim::SimRack>(std::move(config));
    rack_->add_device(sim::default_slave_options(mac(kGood)), std::nullopt);
    broken_.emplace(rack_->world(), mac(kBroken), behaviour, status, additional);
    counter_.emplace(rack_->world());
    rack_->start();
    ASSERT_TRUE(rack_->world().run_until(
        [&] { return rack_->pumps().pump(mac(kGood))->state == NodeState::kOnline; }, seconds(10)));
  }

  // Runs a minute; the broken node's frames per second, and checks that the
  // good node was polled at its period (100 ms) all along.
  double minute_of_frames() {
    const std::uint64_t frames_before = counter_->of(kBroken);
    const std::uint64_t polls_before = node(kGood).counters().polls;
    const std::uint64_t responses_before = node(kGood).counters().responses;
    rack_->world().run_for(seconds(60));
    const auto polls = node(kGood).counters().polls - polls_before;
    EXPECT_GE(polls, 599u) << "the good node was not polled every 100 ms";
    EXPECT_LE(polls, 601u);
    // Every poll answered (one may be in flight at either end of the minute).
    EXPECT_NEAR(static_cast<double>(node(kGood).counters().responses - responses_before),
                static_cast<double>(polls), 1.0);
    EXPECT_EQ(rack_->pumps().pump(mac(kGood))->state, NodeState::kOnline);
    const double rate = static_cast<double>(counter_->of(kBroken) - frames_before) / 60.0;
    std::printf("broken node: %.2f frames/s over a minute (%s)\n", rate,
                std::string(devicenet::to_string(node(kBroken).state())).c_str());
    return rate;
  }
  const devicenet::Node& node(unsigned m) { return *rack_->scanner().node(mac(m)); }

  std::unique_ptr<sim::SimRack> rack_;
  std::optional<BrokenNode> broken_;
  std::optional<FrameCounter> counter_;
};

// The bound the README states: a node that cannot be brought online costs
// the bus at most this, averaged over a minute, whatever it answers.
constexpr double kMaxFramesPerSecond = 1.5;

TEST_F(StartupBackoff, SilentNode) {
  build(BrokenNode::Behaviour::kSilent);
  EXPECT_LE(minute_of_frames(), kMaxFramesPerSecond);
  EXPECT_EQ(node(kBroken).state(), NodeState::kAbsent);
}

TEST_F(StartupBackoff, NodeThatKeepsSayingAlreadyAllocated) {
  // Allocate: 0x0B already in requested mode; Release: the same.
  build(BrokenNode::Behaviour::kRefuse, GeneralStatus::kAlreadyInRequestedMode, 0x02);
  EXPECT_LE(minute_of_frames(), kMaxFramesPerSecond);
  EXPECT_EQ(node(kBroken).state(), NodeState::kAbsent);
}

TEST_F(StartupBackoff, NodeInStateConflict) {
  build(BrokenNode::Behaviour::kRefuse, GeneralStatus::kObjectStateConflict, 0xFF);
  EXPECT_LE(minute_of_frames(), kMaxFramesPerSecond);
  EXPECT_EQ(node(kBroken).state(), NodeState::kConfigurationFault);
}

TEST_F(StartupBackoff, NodeOwnedByAnotherMaster) {
  build(BrokenNode::Behaviour::kRefuse, GeneralStatus::kObjectStateConflict, 0x01);
  EXPECT_LE(minute_of_frames(), kMaxFramesPerSecond);
  EXPECT_EQ(node(kBroken).state(), NodeState::kOwnedByOtherMaster);
}

TEST_F(StartupBackoff, NodeThatAllocatesAndThenFallsSilent) {
  build(BrokenNode::Behaviour::kAllocateThenSilent);
  EXPECT_LE(minute_of_frames(), kMaxFramesPerSecond);
  EXPECT_NE(node(kBroken).state(), NodeState::kOnline);
  EXPECT_GT(node(kBroken).counters().explicit_retries, 0u) << "lost requests are retried";
  EXPECT_GT(node(kBroken).counters().allocate_attempts, 3u) << "a lost node is allocated again";
}

// Retries of nodes that failed together do not stay together.
TEST_F(StartupBackoff, RetriesOfTwoSilentNodesDrift) {
  auto config = rack_config({7, 8});
  config.create_devices = false;
  rack_ = std::make_unique<sim::SimRack>(std::move(config));
  std::map<unsigned, std::vector<TimePoint>> allocates;
  rack_->world().bus().set_tap([&](const sim::WireFrame& f) {
    auto id = devicenet::decode_identifier(f.frame.id);
    if (id && id->group == devicenet::MessageGroup::k2 && id->message_id == 6) {
      allocates[id->mac.value()].push_back(f.end);
    }
  });
  rack_->start();
  rack_->world().run_for(seconds(30));
  ASSERT_GE(allocates[7].size(), 6u);
  ASSERT_GE(allocates[8].size(), 6u);
  // Each Allocate waits for its response timeout (2 s), then the back-off:
  // 250 ms doubling to 5 s, -25..+25 %. The two nodes' intervals differ.
  const auto gap = [&](unsigned m, std::size_t i) { return allocates[m][i + 1] - allocates[m][i]; };
  EXPECT_NE(gap(7, 4), gap(8, 4));
  for (unsigned m : {7u, 8u}) {
    for (std::size_t i = 0; i + 1 < allocates[m].size(); ++i) {
      EXPECT_GE(gap(m, i), milliseconds(2000 + 187)) << "MAC " << m << " interval " << i;
      EXPECT_LE(gap(m, i), milliseconds(2000 + 6250 + 1)) << "MAC " << m << " interval " << i;
    }
  }
}

// With a long maximum (allocate_retry_max_ms up to an hour), the jitter is
// still -25..+25 % of it.
TEST(StartupBackoffLongMaximum, JitterSpansBothSidesOfTheMaximum) {
  auto config = rack_config({7});
  config.create_devices = false;
  config.port.allocate_retry_max = seconds(60);
  sim::SimRack rack(std::move(config));
  std::vector<TimePoint> allocates;
  rack.world().bus().set_tap([&](const sim::WireFrame& f) {
    if (f.frame.id ==
        devicenet::group2_id(mac(7), devicenet::Group2Message::kUnconnectedExplicitRequest)) {
      allocates.push_back(f.end);
    }
  });
  rack.start();
  rack.world().run_for(seconds(3600));
  // 250 ms doubling: 60 s is reached at the 9th retry; after it, each
  // interval is the 2 s response timeout plus 45..75 s.
  ASSERT_GE(allocates.size(), 40u);
  Duration shortest = Duration::max(), longest{};
  for (std::size_t i = 10; i + 1 < allocates.size(); ++i) {
    const Duration gap = allocates[i + 1] - allocates[i];
    shortest = std::min(shortest, gap);
    longest = std::max(longest, gap);
    EXPECT_GE(gap, seconds(2 + 45) - milliseconds(1));
    EXPECT_LE(gap, seconds(2 + 75) + milliseconds(1));
  }
  EXPECT_LT(shortest, seconds(2 + 52)) << "jitter below the maximum";
  EXPECT_GT(longest, seconds(2 + 68)) << "jitter above the maximum";
}

// ---------------------------------------------------------------------------
// The bus back after bus-off or an interface down: the master's own MAC first.

TEST(BusRecovery, TheMasterChecksItsMacAgainBeforeItScans) {
  auto config = rack_config({kGood});
  sim::SimRack rack(std::move(config));
  EventRecorder events;
  rack.observe(events);
  std::vector<std::pair<TimePoint, std::uint32_t>> frames;  // the master's
  rack.world().bus().set_tap([&](const sim::WireFrame& f) {
    if (f.sender == rack.master().handle()) frames.emplace_back(f.end, f.frame.id);
  });
  rack.start();
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(10)));

  frames.clear();
  const TimePoint back = rack.now();
  rack.scanner().recheck_mac("bus-off recovered", back);
  EXPECT_EQ(rack.scanner().state(), devicenet::PortState::kCheckingMac);
  EXPECT_NE(events.port_reason.find("bus-off recovered: checking again"), std::string::npos)
      << events.port_reason;
  EXPECT_EQ(rack.pumps().pump(mac(kGood))->state, NodeState::kAbsent);
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(10)));

  // Two duplicate MAC ID requests of the master's MAC 0, 1 s apart, and
  // nothing else from the master until the second one's second is over.
  const std::uint32_t check =
      devicenet::group2_id(mac(0), devicenet::Group2Message::kDuplicateMacCheck);
  std::vector<TimePoint> checks;
  TimePoint first_other = kNever;
  std::uint32_t first_other_id = 0;
  for (const auto& [at, id] : frames) {
    if (id == check) {
      checks.push_back(at);
    } else if (first_other == kNever && !checks.empty() && at > checks[0] + milliseconds(1)) {
      // (A frame the master had queued before the bus came back may still
      // follow the first check within a frame's time.)
      first_other = at;
      first_other_id = id;
    }
  }
  ASSERT_EQ(checks.size(), 2u);
  EXPECT_LT(checks[0] - back, milliseconds(1));
  EXPECT_GE(checks[1] - checks[0], milliseconds(999));
  EXPECT_GE(first_other - checks[1], milliseconds(999))
      << "the master spoke during its MAC check: 0x" << std::hex << first_other_id;
  EXPECT_EQ(rack.scanner().node(mac(kGood))->counters().reconnects, 1u);
}

// ---------------------------------------------------------------------------
// Serial numbers.

TEST(SerialPinning, AnotherSerialIsAWrongDeviceNeverPolled) {
  auto config = rack_config({kGood});
  config.pumps[0].node.serial_number = 0x4242;
  sim::SimRack rack(std::move(config));
  rack.start();
  const auto& view = *rack.pumps().pump(mac(kGood));
  ASSERT_TRUE(
      rack.world().run_until([&] { return view.state == NodeState::kWrongDevice; }, seconds(10)));
  // default_slave_options: serial 0x10000 + MAC, on the wire as a UINT.
  EXPECT_NE(view.reason.find("the configuration expects 0x00004242"), std::string::npos)
      << view.reason;
  rack.world().run_for(seconds(30));
  EXPECT_EQ(rack.scanner().node(mac(kGood))->counters().polls, 0u);
  EXPECT_EQ(view.state, NodeState::kWrongDevice);
}

TEST(SerialPinning, TheRightSerialComesOnline) {
  auto config = rack_config({kGood});
  config.create_devices = false;
  config.pumps[0].node.serial_number = 0x4242;
  sim::SimRack rack(std::move(config));
  sim::SlaveOptions o = sim::default_slave_options(mac(kGood));
  o.serial_number = 0x4242;
  rack.add_device(o, std::nullopt);
  rack.start();
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(10)));
  EXPECT_EQ(rack.scanner().node(mac(kGood))->identity().serial_number, 0x4242u);
}

TEST(SerialPinning, WithoutAPinAnotherDeviceAtTheMacIsWarnedOf) {
  auto config = rack_config({kGood});
  config.create_devices = false;
  CountingLogSink log;
  sim::SimRack rack(std::move(config), &log);
  sim::SlaveOptions first = sim::default_slave_options(mac(kGood));
  first.serial_number = 0x1111;
  rack.add_device(first, std::nullopt);
  rack.start();
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(10)));
  EXPECT_EQ(log.warnings, 0u) << log.last_warning;

  // The module is swapped for another with the same MAC switch setting.
  rack.device(mac(kGood)).disconnect();
  sim::SlaveOptions second = first;
  second.serial_number = 0x2222;
  sim::SimSlave other(rack.world(), second, rack.now());
  ASSERT_TRUE(rack.world().run_until(
      [&] {
        return rack.scanner().node(mac(kGood))->identity().serial_number == 0x2222u &&
               rack.all_online();
      },
      seconds(30)));
  EXPECT_NE(log.last_warning.find("serial number changed from 0x00001111 to 0x00002222"),
            std::string::npos)
      << log.last_warning;
}

}  // namespace
}  // namespace dnbridge::test
