// `dnbctl racks`, the real program run as a child process, against three
// racks' bridges on one domain, all in this process:
// - rack-north: three CDN127s; pump 1 commanded by this test (online), 2
//   and 3 without a commander (idle);
// - rack-south: pump 1 idle, pump 2 configured but not on the bus (absent),
//   pump 3 not the device the configuration expects (wrong device: faulted),
//   pump 4 held by another DeviceNet master on the same bus;
// - rack-east: a bridge's participant that publishes nothing (yet).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/daemon.hpp"
#include "adapters/daemon/log_sink.hpp"
#include "adapters/daemon/simulated_backends.hpp"
#include "adapters/dds/fields.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/topic.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/dnbctl/client.hpp"
#include "adapters/dnbctl/commander.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/sim/world/sim_backend.hpp"
#include "adapters/sim/world/sim_master.hpp"
#include "adapters/sim/world/sim_rack.hpp"
#include "adapters/sim/world/sim_slave.hpp"
#include "bridge/rack/pump_rack.hpp"
#include "subprocess.hpp"
#include "test_domain.hpp"

namespace dnbridge::dnbctl {
namespace {

using testing::RunResult;
using testing::test_domain;

// Bounds the wait for the racks to reach the states under test.
constexpr auto kReady = std::chrono::seconds(20);

devicenet::MacId mac(unsigned v) { return *devicenet::MacId::from(v); }

// The simulated bus of a port, with a CDN127 at each of `devices` and at
// `held`, and another master (MAC 62) that takes node `held` long before the
// bridge's master has finished its own duplicate MAC check (2 s): the device
// at `held` and the other master check their MACs in 20 ms, and the other
// master asks for the node every 100 ms. Everything runs on the port's
// thread, as the bus does.
class BusWithAnotherMaster final : public port::CanBackend {
 public:
  BusWithAnotherMaster(const daemon::PortConfig& port, const std::vector<devicenet::MacId>& devices,
                       devicenet::MacId held)
      : bus_(port.bitrate, devices),
        held_(bus_.world(), held_options(held), bus_.world().now()),
        other_(bus_.world(), other_config(port, held), observer_) {
    other_.scanner().start(bus_.world().now());
  }

  can::FrameSink& sink() override { return bus_.sink(); }
  TimePoint now() const override { return bus_.now(); }
  void wait(TimePoint deadline, port::FrameReceiver& receiver) override {
    bus_.wait(deadline, receiver);
  }
  void wake() override { bus_.wake(); }
  port::BusCounters counters() const override { return bus_.counters(); }
  std::string interface_name() const override { return bus_.interface_name(); }
  std::uint32_t bitrate() const override { return bus_.bitrate(); }

 private:
  static sim::SlaveOptions held_options(devicenet::MacId held) {
    sim::SlaveOptions o = sim::default_slave_options(held);
    o.duplicate_mac_window = milliseconds(10);
    return o;
  }

  static devicenet::ScannerConfig other_config(const daemon::PortConfig& port,
                                               devicenet::MacId held) {
    devicenet::ScannerConfig c;
    c.master_mac = mac(62);
    c.duplicate_mac_window = milliseconds(10);
    c.explicit_messaging.response_timeout = milliseconds(50);
    c.allocate_retry_min = milliseconds(50);
    c.allocate_retry_max = milliseconds(50);
    std::vector<rack::PumpConfig> pumps;
    for (const auto& n : port.nodes) {
      if (n.pump.node.mac == held) pumps.push_back(n.pump);
    }
    return rack::PumpRack::scanner_config(c, pumps);
  }

  sim::SimBackend bus_;
  sim::SimSlave held_;
  devicenet::ScannerObserver observer_;  // what the other master sees is not under test
  sim::SimMaster other_;
};

daemon::DaemonConfig north_config() {
  daemon::DaemonConfig c = daemon::embedded_default_config();
  c.rack = "rack-north";
  c.domain_id = test_domain();
  c.ports.at(0).nodes.resize(3);  // pumps 1..3
  return c;
}

daemon::DaemonConfig south_config() {
  daemon::DaemonConfig c = daemon::parse_config(R"(
rack = "rack-south"
[[port]]
name = "A"
interface = "simulated"
bitrate = 500000
explicit_response_timeout_ms = 200
  [[port.node]]
  mac = 1
  name = "pump-1"
  [[port.node]]
  mac = 2
  name = "pump-2"
  [[port.node]]
  mac = 3
  name = "pump-3"
  identity = { vendor_id = 59, product_type = 27, product_code = 1999 }
  [[port.node]]
  mac = 4
  name = "pump-4"
)",
                                                "rack-south test configuration");
  c.domain_id = test_domain();
  return c;
}

// Every run of blanks as one space: table columns and JSON indentation vary
// with the widths, the content under test does not.
std::string squeeze(const std::string& text) {
  return std::regex_replace(text, std::regex("[ \n]+"), " ");
}

class DnbctlRacks : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    log_ = std::make_unique<daemon::StderrLogSink>(LogLevel::kError);
    north_ = std::make_unique<daemon::Daemon>(north_config(), *log_,
                                              daemon::simulated_backend_factory(*log_));
    north_->start();
    south_ = std::make_unique<daemon::Daemon>(
        south_config(), *log_,
        [](const daemon::PortConfig& p) -> std::unique_ptr<port::CanBackend> {
          return std::make_unique<BusWithAnotherMaster>(p, std::vector{mac(1), mac(3)}, mac(4));
        });
    south_->start();
    east_ =
        std::make_unique<dds::Participant>(static_cast<dds_domainid_t>(test_domain()), "rack-east");
  }

  static void TearDownTestSuite() {
    east_.reset();
    if (south_) south_->stop();
    south_.reset();
    if (north_) north_->stop();
    north_.reset();
    log_.reset();
  }

  static RunResult dnbctl(std::vector<std::string> args) {
    args.insert(args.begin(), {"--domain", std::to_string(test_domain())});
    return testing::run(DNBCTL_PATH, args);
  }

  static std::unique_ptr<daemon::StderrLogSink> log_;
  static std::unique_ptr<daemon::Daemon> north_;
  static std::unique_ptr<daemon::Daemon> south_;
  static std::unique_ptr<dds::Participant> east_;
};

std::unique_ptr<daemon::StderrLogSink> DnbctlRacks::log_;
std::unique_ptr<daemon::Daemon> DnbctlRacks::north_;
std::unique_ptr<daemon::Daemon> DnbctlRacks::south_;
std::unique_ptr<dds::Participant> DnbctlRacks::east_;

TEST_F(DnbctlRacks, ShowsEachRacksNodesByClassWithTheReason) {
  ASSERT_TRUE(north_ && south_ && east_);
  // A supervisor of north's pump 1, live for the whole test.
  Client supervisor(test_domain(), "racks test supervisor");
  Commander<dnbridge_PumpCommand> commander(supervisor, 10, "rack-north");
  ASSERT_TRUE(commander.wait_matched(supervisor, deadline_after(kReady)));
  const auto state = [&](const char* rack, unsigned m) {
    const auto* n = supervisor.node({rack, "A", static_cast<std::uint8_t>(m)});
    return n ? n->data->state : dnbridge_NODE_STOPPED;
  };
  // A command applies only to an online node: written once it is.
  ASSERT_TRUE(supervisor.wait_until(
      deadline_after(kReady), [&] { return state("rack-north", 1) == dnbridge_NODE_ONLINE; }));
  ASSERT_TRUE(commander.write({"rack-north", "A", 1}, Outputs{true, false, 0}, "racks test"));

  const auto outputs_idle = [&](const char* rack, unsigned m) {
    const auto* p = supervisor.pump({rack, "A", static_cast<std::uint8_t>(m)});
    return !p || p->data->outputs_idle;
  };
  const bool ready = supervisor.wait_until(deadline_after(kReady), [&] {
    const auto* absent = supervisor.node({"rack-south", "A", 2});
    return state("rack-north", 1) == dnbridge_NODE_ONLINE && !outputs_idle("rack-north", 1) &&
           state("rack-north", 2) == dnbridge_NODE_ONLINE && outputs_idle("rack-north", 2) &&
           state("rack-north", 3) == dnbridge_NODE_ONLINE && outputs_idle("rack-north", 3) &&
           state("rack-south", 1) == dnbridge_NODE_ONLINE && outputs_idle("rack-south", 1) &&
           absent && absent->data->state == dnbridge_NODE_ABSENT &&
           !dds::view(absent->data->last_error).empty() &&
           state("rack-south", 3) == dnbridge_NODE_WRONG_DEVICE &&
           state("rack-south", 4) == dnbridge_NODE_OWNED_BY_OTHER_MASTER;
  });
  if (!ready) {
    std::string seen;
    for (const auto& [k, n] : supervisor.nodes()) {
      const auto* p = supervisor.pump(k);
      seen += node_name(k.rack, k.port, k.mac) + ": " + std::string(to_text(n.data->state)) + ", " +
              std::string(dds::view(n.data->reason)) +
              (p && !p->data->outputs_idle ? "" : ", idle") +
              ", last error: " + std::string(dds::view(n.data->last_error)) + "\n";
    }
    FAIL() << "the racks did not reach the states under test; seen:\n" << seen;
  }

  // rack-east publishes nothing: dnbctl waits for it until the timeout.
  const auto text = dnbctl({"racks", "--timeout", "2"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.err.find("no status from the bridge of rack-east"), std::string::npos) << text.err;
  const std::string t = squeeze(text.out);
  for (const char* expected : {
           "RACK BRIDGE PORTS NODES ONLINE IDLE STARTING ABSENT FAULTED OTHER MASTER STOPPED "
           "UNKNOWN rack-east no status yet - - - - - - - - - - "
           "rack-north live 1/1 running 3 1 2 0 0 0 0 0 0 "
           "rack-south live 1/1 running 4 0 1 0 1 1 1 0 0 ",
           "RACK PORT MAC NAME CLASS STATE REASON "
           "rack-north A 2 pump-2 idle online no command yet: idle polls, the device holds its "
           "configured idle state "
           "rack-north A 3 pump-3 idle online no command yet: ",
           "rack-south A 1 pump-1 idle online no command yet: idle polls, the device holds its "
           "configured idle state "
           "rack-south A 2 pump-2 absent absent waiting for the first Allocate (",
           " Allocate attempts; last error: explicit request timed out) "
           "rack-south A 3 pump-3 faulted wrong device expected vendor 59 product type 27 "
           "product code 1999, found vendor 59 product type 27 product code 1888 "
           "rack-south A 4 pump-4 owned by another master owned by another master Allocate "
           "refused: "
           "owned by another master (0x0C/0x01) ",
       }) {
    EXPECT_NE(t.find(expected), std::string::npos) << "missing: " << expected << "\nin:\n"
                                                   << text.out;
  }
  // Online nodes are counted, not listed; every port runs on a healthy bus.
  EXPECT_EQ(t.find("rack-north A 1 "), std::string::npos) << text.out;
  EXPECT_EQ(t.find("RACK PORT STATE BUS REASON"), std::string::npos) << text.out;

  const auto json = dnbctl({"racks", "--json", "--timeout", "2"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const std::string j = squeeze(json.out);
  // The bridges run in this process, rack-east's participant says nothing.
  char host[256] = {};
  ASSERT_EQ(gethostname(host, sizeof host - 1), 0);
  const std::string here = fmt::format(R"j("bridge_hosts": [ "{} (pid {})" ], )j", host, getpid());
  const std::string expected_json[] = {
      R"j({ "racks": [ { "rack": "rack-east", "bridge": "no status yet", "participants": 1, )j"
      R"j("bridge_hosts": [ "" ], "counts": { "nodes": 0, )j",
      R"j({ "rack": "rack-north", "bridge": "live", "participants": 1, )j" + here +
          R"j("counts": { "nodes": 3, "online": 1, "idle": 2, "starting": 0, "absent": 0, )j"
          R"j("faulted": 0, "owned_by_other_master": 0, "stopped": 0, "unknown": 0 }, )j"
          R"j("ports": [ { "port": "A", "state": "running", )j",
      R"j("mac": 1, "name": "pump-1", "class": "online", "state": "online", )j"
      R"j("reason": "polled )j",
      R"j("outputs_idle": false, "commanded_by": "racks test" })j",
      R"j({ "rack": "rack-south", "bridge": "live", "participants": 1, )j" + here +
          R"j("counts": { "nodes": 4, "online": 0, "idle": 1, "starting": 0, "absent": 1, )j"
          R"j("faulted": 1, "owned_by_other_master": 1, "stopped": 0, "unknown": 0 }, )j",
      R"j("mac": 2, "name": "pump-2", "class": "absent", "state": "absent", )j",
      R"j("mac": 3, "name": "pump-3", "class": "faulted", "state": "wrong device", )j",
      R"j("mac": 4, "name": "pump-4", "class": "owned_by_other_master", )j"
      R"j("state": "owned by another master", )j"
      R"j("reason": "Allocate refused: owned by another master (0x0C/0x01)", )j",
  };
  for (const std::string& expected : expected_json) {
    EXPECT_NE(j.find(expected), std::string::npos) << "missing: " << expected << "\nin:\n"
                                                   << json.out;
  }

  // --rack: that rack alone.
  const auto south = dnbctl({"racks", "--rack", "rack-south"});
  ASSERT_EQ(south.exit_code, 0) << south.err;
  EXPECT_NE(squeeze(south.out).find("rack-south live 1/1 running 4 0 1 0 1 1 1 0 0"),
            std::string::npos)
      << south.out;
  EXPECT_EQ(south.out.find("rack-north"), std::string::npos) << south.out;
  EXPECT_EQ(south.out.find("rack-east"), std::string::npos) << south.out;
}

// Commands and requests travel in their rack's partition: a writer for
// rack-south reaches south's bridge alone, one with no partition (a
// supervisor written before partitions) reaches none; a reader of every
// rack's replies finds both bridges' reply writers.
TEST_F(DnbctlRacks, CommandsAndRequestsReachTheirRacksBridgeOnly) {
  ASSERT_TRUE(north_ && south_);
  Client supervisor(test_domain(), "partitions test");
  dds::Topic<dnbridge_PumpCommand> commands(supervisor.participant());
  dds::Topic<dnbridge_ExplicitRequest> requests(supervisor.participant());
  dds::Topic<dnbridge_ExplicitReply> replies(supervisor.participant());
  dds::Writer<dnbridge_PumpCommand> south(
      supervisor.participant(), commands,
      dds::command_writer_qos(dds::rack_partitions("rack-south"), 10, seconds(1)));
  dds::Writer<dnbridge_PumpCommand> nowhere(
      supervisor.participant(), commands,
      dds::command_writer_qos(std::vector<std::string>{}, 10, seconds(1)));
  dds::Writer<dnbridge_ExplicitRequest> to_north(
      supervisor.participant(), requests,
      dds::request_writer_qos(dds::rack_partitions("rack-north")));
  dds::Reader<dnbridge_ExplicitReply> every(
      supervisor.participant(), replies,
      dds::reply_reader_qos(std::vector<std::string>{std::string(dds::kEveryRackPartition)}));
  const auto matched = [](const auto& entity) -> std::uint32_t {
    if constexpr (requires { entity.matched_subscriptions(); }) {
      auto n = entity.matched_subscriptions();
      return n.ok() ? *n : 0;
    } else {
      auto n = entity.matched_publications();
      return n.ok() ? *n : 0;
    }
  };
  // Discovery is local (one process): a moment at most; bounded.
  ASSERT_TRUE(supervisor.wait_until(deadline_after(kReady), [&] {
    return matched(south) >= 1 && matched(to_north) >= 1 && matched(every) >= 2;
  }));
  EXPECT_EQ(matched(south), 1u);
  EXPECT_EQ(matched(to_north), 1u);
  EXPECT_EQ(matched(every), 2u);
  EXPECT_EQ(matched(nowhere), 0u);
}

}  // namespace
}  // namespace dnbridge::dnbctl
