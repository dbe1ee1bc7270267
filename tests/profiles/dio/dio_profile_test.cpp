// The test-only profile "dio" through the bridge's shared paths, as a
// product profile would go: the port loop brings its node up with its safe
// state downloaded, the publisher writes its own topic and NodeStatus, the
// DDS input hands its commands to the node, and a departing commander
// leaves the outputs idle. Nothing of the bridge names the profile: it is
// registered in dio_profiles() and its nodes are in the port's PortNodes.
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adapters/daemon/dds_input.hpp"
#include "adapters/daemon/dds_publisher.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/port/port_loop.hpp"
#include "adapters/sim/world/sim_backend.hpp"
#include "dds/dds_fixture.hpp"
#include "profiles/dio/dio_topics.hpp"
#include "support/example_eds.hpp"

namespace dnbridge::test::dio {
namespace {

using dds::testing::kEventTimeout;
using dds::testing::test_domain;
using devicenet::MacId;
using SteadyClock = std::chrono::steady_clock;

constexpr unsigned kMac = 20;
constexpr const char* kPort = "A";
const MacId kNode = *MacId::from(kMac);

// A reader that keeps the last sample of its node with data, waited for
// (bounded) until it shows what a test expects.
template <class T>
class LastSample {
 public:
  LastSample(const dds::Participant& participant, const dds::Qos& qos)
      : topic_(participant),
        reader_(participant, topic_, qos),
        fresh_(reader_, DDS_NOT_READ_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ANY_INSTANCE_STATE),
        waitset_(participant) {
    waitset_.attach(fresh_, 1);
  }
  bool until(const std::function<bool(const T&)>& done, Duration timeout = kEventTimeout) {
    const auto deadline = SteadyClock::now() + timeout;
    for (;;) {
      for (auto taken = reader_.take(); taken.ok() && !taken->empty(); taken = reader_.take()) {
        for (auto& s : *taken) {
          if (s.info().valid_data() && s.data().mac == kMac) last_ = std::move(s);
        }
      }
      if (last_ && done(last_->data())) return true;
      const auto now = SteadyClock::now();
      if (now >= deadline) return false;
      (void)waitset_.wait(deadline - now);
    }
  }
  const T& last() const { return last_->data(); }

 private:
  dds::Topic<T> topic_;
  dds::Reader<T> reader_;
  dds::ReadCondition fresh_;
  dds::WaitSet waitset_;
  std::optional<dds::Sample<T>> last_;
};

DioConfig io_block() {
  DioConfig io;
  io.node.mac = kNode;
  io.node.name = "io block";
  io.node.poll_period = milliseconds(20);
  io.node.expected_packet_rate = milliseconds(100);
  io.fault_outputs = 0x01;
  io.idle_outputs = 0x80;
  return io;
}

// The port, with the I/O block in its scan list or none.
port::PortLoopConfig port_config(bool with_io_block) {
  port::PortLoopConfig c;
  c.port = kPort;
  c.scanner.master_mac = *MacId::from(0);
  c.status_period = milliseconds(200);
  if (with_io_block) c.nodes.of<DioConfig>().push_back(io_block());
  return c;
}

class DioProfileTest : public ::testing::Test {
 protected:
  DioProfileTest()
      : rack_(::testing::UnitTest::GetInstance()->current_test_info()->name()),
        bridge_(test_domain(), rack_),
        publisher_(bridge_, rack_, seconds(1), Logger(), dio_profiles()) {}
  ~DioProfileTest() override {
    if (input_) input_->stop();
    if (loop_) loop_->stop();
  }

  void start(bool with_io_block) {
    auto backend = std::make_unique<sim::SimBackend>(
        can::kBitrate500k, std::vector<MacId>{}, nullptr,
        std::vector<sim::EdsDeviceSpec>{
            {kNode, std::make_shared<const profiles::eds::EdsFile>(example_eds(kIoBlockEds))}});
    loop_.emplace(port_config(with_io_block), std::move(backend), publisher_, null_log_sink());
    input_.emplace(bridge_, publisher_, rack_,
                   std::map<std::string, port::PortLoop*, std::less<>>{{kPort, &*loop_}}, Logger(),
                   std::function<void(daemon::ReloadCall)>{}, dds::kDefaultMaxCommanderLease,
                   dio_profiles());
    loop_->start();
    input_->start();
  }

  // Runs `fn` on the simulated I/O block, on the port's thread; false when
  // the port did not run it in time.
  bool on_device(std::function<void(sim::EdsSlave&)> fn) {
    // Shared with the posted function, which may run after a timeout here.
    auto done = std::make_shared<std::promise<void>>();
    auto future = done->get_future();
    loop_->post([done, fn = std::move(fn)](port::CanBackend& backend) {
      fn(static_cast<sim::SimBackend&>(backend).eds_device(kNode).device());
      done->set_value();
    });
    return future.wait_for(kEventTimeout) == std::future_status::ready;
  }
  // The device's Parameter `n`; -1 when it cannot be read.
  double param(unsigned n) {
    auto value = std::make_shared<double>(-1);
    EXPECT_TRUE(on_device([value, n](sim::EdsSlave& device) {
      *value = device.objects().param_number(n).value_or(-1);
    }));
    return *value;
  }
  bool set_param(unsigned n, std::uint8_t v) {
    auto set = std::make_shared<bool>(false);
    const bool ran = on_device([set, n, v](sim::EdsSlave& device) {
      const std::vector<std::uint8_t> bytes{v};
      *set = device.objects().set_param_value(n, Bytes(bytes));
    });
    return ran && *set;
  }

  // A supervisor's command of the I/O block's outputs, written until the
  // writer is dropped.
  struct Commander {
    Commander(const dds::Participant& participant, const std::string& rack)
        : topic(participant),
          writer(participant, topic,
                 dds::command_writer_qos(dds::rack_partitions(rack), 10, seconds(1))) {}
    dds::Topic<dnbridge_test_DioCommand> topic;
    dds::Writer<dnbridge_test_DioCommand> writer;
  };
  bool command(Commander& commander, std::uint8_t outputs) {
    if (!dds::testing::until_matched(supervisor_, commander.writer)) return false;
    dds::Owned<dnbridge_test_DioCommand> c;
    dds::set_string(c->rack, rack_);
    dds::set_string(c->port, kPort);
    c->mac = kMac;
    c->outputs = outputs;
    dds::set_string(c->issuer, "dio-supervisor");
    return commander.writer.write(*c).ok();
  }

  std::string rack_;
  dds::Participant bridge_;
  daemon::DdsPublisher publisher_;
  std::optional<port::PortLoop> loop_;
  std::optional<daemon::DdsInput> input_;
  dds::Participant supervisor_{test_domain(), dds::Participant::ClientName{"dio supervisor"}};
  LastSample<dnbridge_test_DioState> states_{supervisor_, dds::state_reader_qos()};
  LastSample<dnbridge_NodeStatus> statuses_{supervisor_, dds::state_reader_qos()};
};

TEST_F(DioProfileTest, ItsNodeIsPublishedOnItsOwnTopicAndCommandedThroughTheSharedPaths) {
  start(true);
  // Online, its safe state downloaded and read back.
  ASSERT_TRUE(states_.until([](const auto& s) { return s.online && s.inputs_valid; }));
  EXPECT_EQ(param(7), 0x01);
  EXPECT_EQ(param(9), 0x80);
  ASSERT_TRUE(statuses_.until([](const auto& s) { return s.safe_state_known; }));
  EXPECT_STREQ(statuses_.last().safe_state_text, "outputs on a fault 0x01, when idle 0x80");
  EXPECT_EQ(statuses_.last().state, dnbridge_NODE_ONLINE);
  EXPECT_TRUE(states_.last().outputs_idle);

  // Inputs from the device reach the topic.
  ASSERT_TRUE(set_param(3, 0xA5));
  ASSERT_TRUE(states_.until([](const auto& s) { return s.inputs == 0xA5; }))
      << "inputs 0x" << std::hex << int{states_.last().inputs};

  // A supervisor commands the outputs through the profile's command topic.
  {
    Commander commander(supervisor_, rack_);
    ASSERT_TRUE(command(commander, 0x81));
    ASSERT_TRUE(states_.until([](const auto& s) { return !s.outputs_idle && s.outputs == 0x81; }))
        << states_.last().idle_reason;
    EXPECT_STREQ(states_.last().commanded_by, "dio-supervisor");
    EXPECT_EQ(param(4), 0x81);
  }
  // Its writer gone, no commander is left: idle, and the device holds its
  // configured idle value.
  ASSERT_TRUE(states_.until([](const auto& s) { return s.outputs_idle; }));
  EXPECT_STREQ(states_.last().commanded_by, "");
  EXPECT_EQ(param(4), 0x80);
}

// A port that had no node of the profile gets one by a reload: its rack is
// made then, and the DDS input, on Cyclone's threads, finds the node's
// profile and hands it its commands.
TEST_F(DioProfileTest, AReloadBringsTheProfileToAPortThatHadNone) {
  start(false);
  auto change = loop_->reconfigure(port_config(true));
  ASSERT_EQ(change.wait_for(kEventTimeout), std::future_status::ready);
  const port::PortChange applied = change.get();
  ASSERT_TRUE(applied.refused.empty()) << applied.refused;
  ASSERT_EQ(applied.scan_list.added, std::vector<MacId>{kNode});
  EXPECT_EQ(loop_->profile_of(kNode), DioProfile::kName);

  ASSERT_TRUE(states_.until([](const auto& s) { return s.online && s.inputs_valid; }));
  Commander commander(supervisor_, rack_);
  ASSERT_TRUE(command(commander, 0x42));
  ASSERT_TRUE(states_.until([](const auto& s) { return !s.outputs_idle && s.outputs == 0x42; }))
      << states_.last().idle_reason;
  EXPECT_EQ(param(4), 0x42);
}

}  // namespace
}  // namespace dnbridge::test::dio
