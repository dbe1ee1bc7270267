// `dnbctl racks` without DDS: every node state's class, the bridges' states,
// the counts, and the parts of the text a live run rarely shows (ports that
// need attention, nodes no bridge publishes any more).
#include "adapters/dnbctl/rack_summary.hpp"

#include <gtest/gtest.h>

#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topics.hpp"

namespace dnbridge::dnbctl {
namespace {

using dds::Owned;
using dds::set_string;

// Samples live here; rows point into them (a deque does not move them).
struct Samples {
  std::deque<Owned<dnbridge_NodeStatus>> nodes;
  std::deque<Owned<dnbridge_PumpState>> pumps;
  std::deque<Owned<dnbridge_PortStatus>> ports;

  NodeRow node(const char* rack, unsigned mac, dnbridge_NodeLifecycle state, const char* reason,
               bool idle = true, bool alive = true) {
    auto& n = nodes.emplace_back();
    set_string(n->rack, rack);
    set_string(n->port, "A");
    n->mac = static_cast<std::uint8_t>(mac);
    set_string(n->name, "pump-" + std::to_string(mac));
    n->state = state;
    set_string(n->reason, reason);
    auto& p = pumps.emplace_back();
    set_string(p->rack, rack);
    set_string(p->port, "A");
    p->mac = n->mac;
    p->online = state == dnbridge_NODE_ONLINE;
    p->outputs_idle = idle;
    if (!idle) set_string(p->commanded_by, "supervisor-1");
    return NodeRow{n.get(), p.get(), alive};
  }

  PortRow port(const char* rack, dnbridge_PortLifecycle state, dnbridge_BusState bus,
               const char* reason, bool alive = true) {
    auto& p = ports.emplace_back();
    set_string(p->rack, rack);
    set_string(p->port, "A");
    p->state = state;
    p->bus_state = bus;
    set_string(p->reason, reason);
    return PortRow{p.get(), alive};
  }
};

TEST(RackSummary, EveryLifeCycleStateHasAClass) {
  Samples s;
  const std::vector<std::pair<dnbridge_NodeLifecycle, NodeClass>> cases{
      {dnbridge_NODE_ABSENT, NodeClass::kAbsent},
      {dnbridge_NODE_IDENTIFYING, NodeClass::kStarting},
      {dnbridge_NODE_CONFIGURING, NodeClass::kStarting},
      {dnbridge_NODE_VERIFYING, NodeClass::kStarting},
      {dnbridge_NODE_ONLINE, NodeClass::kIdle},  // no commander
      {dnbridge_NODE_WRONG_DEVICE, NodeClass::kFaulted},
      {dnbridge_NODE_CONFIGURATION_FAULT, NodeClass::kFaulted},
      {dnbridge_NODE_OWNED_BY_OTHER_MASTER, NodeClass::kOtherMaster},
      {dnbridge_NODE_STOPPED, NodeClass::kStopped},
  };
  for (const auto& [state, expected] : cases) {
    EXPECT_EQ(classify(s.node("r", 1, state, "why")), expected) << state;
  }
  EXPECT_EQ(classify(s.node("r", 1, dnbridge_NODE_ONLINE, "polled", false)), NodeClass::kOnline);
  // The last word of a bridge that left is no state at all.
  EXPECT_EQ(classify(s.node("r", 1, dnbridge_NODE_ONLINE, "polled", false, false)),
            NodeClass::kUnknown);
  EXPECT_EQ(json_name(NodeClass::kOtherMaster), "owned_by_other_master");
  EXPECT_EQ(to_text(NodeClass::kOtherMaster), "owned by another master");
}

TEST(RackSummary, ReasonsSayWhatToLookAt) {
  Samples s;
  const auto absent = s.node("r", 2, dnbridge_NODE_ABSENT, "no answer to Allocate (timed out)");
  auto& status = *s.nodes.back();
  status.counters.allocate_attempts = 1;
  EXPECT_EQ(class_reason(absent), "no answer to Allocate (timed out) (1 Allocate attempt)");
  set_string(status.last_error, "explicit request timed out");
  status.counters.allocate_attempts = 7;
  EXPECT_EQ(class_reason(absent),
            "no answer to Allocate (timed out) (7 Allocate attempts; last error: explicit request "
            "timed out)");
  EXPECT_EQ(class_reason(s.node("r", 1, dnbridge_NODE_ONLINE, "polled every 100 ms", false)),
            "polled every 100 ms; commanded by supervisor-1");
  EXPECT_EQ(class_reason(s.node("r", 1, dnbridge_NODE_ONLINE, "polled every 100 ms")),
            "no commander: idle polls, the device holds its configured idle state");
  EXPECT_EQ(class_reason(s.node("r", 3, dnbridge_NODE_CONFIGURATION_FAULT, "poll sizes differ")),
            "poll sizes differ");
  EXPECT_EQ(class_reason(s.node("r", 1, dnbridge_NODE_ONLINE, "polled", true, false)),
            "no longer published by a bridge; last reported online: polled");
}

TEST(RackSummary, BridgesAreLiveSilentOrGone) {
  Samples s;
  const std::vector<PortRow> ports{
      s.port("live", dnbridge_PORT_RUNNING, dnbridge_BUS_ERROR_ACTIVE, "scanning"),
      s.port("gone", dnbridge_PORT_RUNNING, dnbridge_BUS_ERROR_ACTIVE, "scanning", false)};
  const std::vector<NodeRow> nodes{s.node("live", 1, dnbridge_NODE_ONLINE, "polled", false),
                                   s.node("live", 2, dnbridge_NODE_STOPPED, "orderly shutdown"),
                                   s.node("gone", 1, dnbridge_NODE_ONLINE, "polled", false, false)};
  const auto racks = summarize_racks(
      ports, nodes, {{"live", {"host-a (pid 1)"}}, {"silent", {"", "host-b (pid 2)"}}});
  ASSERT_EQ(racks.size(), 3u);
  EXPECT_EQ(racks[0].rack, "gone");
  EXPECT_EQ(racks[0].bridge, BridgeState::kGone);
  EXPECT_EQ(racks[0].count(NodeClass::kUnknown), 1u);
  EXPECT_EQ(racks[1].rack, "live");
  EXPECT_EQ(racks[1].bridge, BridgeState::kLive);
  EXPECT_EQ(racks[1].count(NodeClass::kOnline), 1u);
  EXPECT_EQ(racks[1].count(NodeClass::kStopped), 1u);
  EXPECT_EQ(racks[2].rack, "silent");
  EXPECT_EQ(racks[2].bridge, BridgeState::kSilent);
  EXPECT_EQ(racks[2].participants, 2u);

  const std::string text = racks_text(racks);
  EXPECT_EQ(
      text.rfind(
          "RACK    BRIDGE                                         PORTS        NODES  ONLINE  "
          "IDLE  STARTING  ABSENT  FAULTED  OTHER MASTER  STOPPED  UNKNOWN\n"
          "gone    gone                                           0/1 running  1      0       "
          "0     0         0       0        0             0        1\n"
          "live    live                                           1/1 running  2      1       "
          "0     0         0       0        0             1        0\n"
          "silent  no status yet (2 bridges!: ?, host-b (pid 2))  -            -      -       "
          "-     -         -       -        -             -        -\n",
          0),
      0u)
      << text;
  // The gone bridge's port needs attention; its node and the stopped one are listed.
  EXPECT_NE(text.find("\nRACK  PORT  STATE        BUS           REASON\n"
                      "gone  A     bridge gone  error-active  scanning\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("gone  A     1    pump-1  unknown  online   no longer published by a bridge; "
                      "last reported online: polled\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("live  A     2    pump-2  stopped  stopped  orderly shutdown\n"),
            std::string::npos)
      << text;
}

TEST(RackSummary, PortsOffTheirBusAreShownAndAnAllOnlineRackSaysSo) {
  Samples s;
  const std::vector<PortRow> ports{
      s.port("r", dnbridge_PORT_RUNNING, dnbridge_BUS_OFF, "can0: bus-off")};
  const std::vector<NodeRow> nodes{s.node("r", 1, dnbridge_NODE_ONLINE, "polled", false)};
  const auto racks = summarize_racks(ports, nodes, {{"r", {"host-a (pid 1)"}}});
  const std::string text = racks_text(racks);
  EXPECT_NE(text.find("\nRACK  PORT  STATE    BUS      REASON\n"
                      "r     A     running  bus-off  can0: bus-off\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("\nevery node reported is online\n"), std::string::npos) << text;

  JsonWriter out(false);
  racks_json(out, racks);
  EXPECT_NE(out.str().find(R"("bus_state":"bus-off",)"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find(R"("bridge_alive":true,"healthy":false})"), std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find(R"({"port":"A","mac":1,"name":"pump-1","class":"online",)"),
            std::string::npos)
      << out.str();
}

}  // namespace
}  // namespace dnbridge::dnbctl
