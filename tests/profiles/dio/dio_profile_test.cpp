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

port::PortLoopConfig port_config() {
  DioConfig io;
  io.node.mac = kNode;
  io.node.name = "io block";
  io.node.poll_period = milliseconds(20);
  io.node.expected_packet_rate = milliseconds(100);
  io.fault_outputs = 0x01;
  io.idle_outputs = 0x80;
  port::PortLoopConfig c;
  c.port = kPort;
  c.scanner.master_mac = *MacId::from(0);
  c.status_period = milliseconds(200);
  c.nodes.of<DioConfig>().push_back(io);
  return c;
}

class DioProfileTest : public ::testing::Test {
 protected:
  DioProfileTest()
      : rack_(::testing::UnitTest::GetInstance()->current_test_info()->name()),
        bridge_(test_domain(), rack_),
        publisher_(bridge_, rack_, seconds(1), Logger(), dio_profiles()) {
    auto backend = std::make_unique<sim::SimBackend>(
        can::kBitrate500k, std::vector<MacId>{}, nullptr,
        std::vector<sim::EdsDeviceSpec>{
            {kNode, std::make_shared<const eds::EdsFile>(example_eds(kIoBlockEds))}});
    loop_.emplace(port_config(), std::move(backend), publisher_, null_log_sink());
    input_.emplace(bridge_, publisher_, rack_,
                   std::map<std::string, port::PortLoop*, std::less<>>{{kPort, &*loop_}}, Logger(),
                   std::function<void(daemon::ReloadCall)>{}, dds::kDefaultMaxCommanderLease,
                   dio_profiles());
    loop_->start();
    input_->start();
  }
  ~DioProfileTest() override {
    input_->stop();
    loop_->stop();
  }

  // The simulated device's Parameter `n`, read on the port's thread.
  double param(unsigned n) {
    std::promise<double> value;
    loop_->post([&](port::CanBackend& backend) {
      auto& device = static_cast<sim::SimBackend&>(backend).eds_device(kNode).device();
      value.set_value(device.objects().param_number(n).value_or(-1));
    });
    return value.get_future().get();
  }
  void set_param(unsigned n, std::uint8_t v) {
    std::promise<bool> done;
    loop_->post([&](port::CanBackend& backend) {
      auto& device = static_cast<sim::SimBackend&>(backend).eds_device(kNode).device();
      const std::vector<std::uint8_t> bytes{v};
      done.set_value(device.objects().set_param_value(n, Bytes(bytes)));
    });
    ASSERT_TRUE(done.get_future().get());
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
  // Online, its safe state downloaded and read back.
  ASSERT_TRUE(states_.until([](const auto& s) { return s.online && s.inputs_valid; }));
  EXPECT_EQ(param(7), 0x01);
  EXPECT_EQ(param(9), 0x80);
  ASSERT_TRUE(statuses_.until([](const auto& s) { return s.safe_state_known; }));
  EXPECT_STREQ(statuses_.last().safe_state_text, "outputs on a fault 0x01, when idle 0x80");
  EXPECT_EQ(statuses_.last().state, dnbridge_NODE_ONLINE);
  EXPECT_TRUE(states_.last().outputs_idle);

  // Inputs from the device reach the topic.
  set_param(3, 0xA5);
  ASSERT_TRUE(states_.until([](const auto& s) { return s.inputs == 0xA5; }))
      << "inputs 0x" << std::hex << int{states_.last().inputs};

  // A supervisor commands the outputs through the profile's command topic.
  {
    dds::Topic<dnbridge_test_DioCommand> topic(supervisor_);
    dds::Writer<dnbridge_test_DioCommand> writer(
        supervisor_, topic, dds::command_writer_qos(dds::rack_partitions(rack_), 10, seconds(1)));
    ASSERT_TRUE(dds::testing::until_matched(supervisor_, writer));
    dds::Owned<dnbridge_test_DioCommand> c;
    dds::set_string(c->rack, rack_);
    dds::set_string(c->port, kPort);
    c->mac = kMac;
    c->outputs = 0x81;
    dds::set_string(c->issuer, "dio-supervisor");
    ASSERT_TRUE(writer.write(*c).ok());
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

}  // namespace
}  // namespace dnbridge::test::dio
