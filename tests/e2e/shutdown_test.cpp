// An orderly stop as the supervisor sees it: the last samples say offline and
// stopped, then every instance is unregistered (NOT_ALIVE_NO_WRITERS), never
// disposed, while the bridge's participant still exists.
#include <map>
#include <string>

#include "bridge_fixture.hpp"

namespace dnbridge::e2e {
namespace {

// The instance state after the last sample of each instance `key` tells
// apart, and the last sample with data of each.
template <class T, class Key>
void expect_unregistered(const Subscription<T>& s, Key key, std::size_t instances,
                         const char* topic) {
  std::map<decltype(key(std::declval<const T&>())), dds::InstanceState> last_state;
  for (const auto& r : s.history()) {
    EXPECT_NE(r.sample.info().instance_state(), dds::InstanceState::kNotAliveDisposed)
        << topic << ": an instance was disposed";
    last_state[key(r.sample.data())] = r.sample.info().instance_state();
  }
  EXPECT_EQ(last_state.size(), instances) << topic;
  for (const auto& [k, state] : last_state) {
    EXPECT_EQ(state, dds::InstanceState::kNotAliveNoWriters) << topic << " instance " << k;
  }
}

TEST_F(BridgeTest, OrderlyStopLeavesLastSamplesThenUnregisters) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  ASSERT_TRUE(ports_.until([&] {
    const auto* p = ports_.latest([](const auto&) { return true; });
    return p && p->nodes_online == kPumps;
  }));

  const auto stopping = SteadyClock::now();
  bridge_->stop();
  report("Daemon::stop()", ms_since(stopping));

  // Every instance of the three state topics ends NOT_ALIVE_NO_WRITERS.
  auto all_gone = [](const auto& history, std::size_t count) {
    std::map<unsigned, bool> gone;
    for (const auto& r : history) {
      unsigned k = 0;
      if constexpr (requires { r.sample->mac; }) k = r.sample->mac;
      gone[k] = r.sample.info().instance_state() == dds::InstanceState::kNotAliveNoWriters;
    }
    if (gone.size() != count) return false;
    for (const auto& [k, g] : gone) {
      if (!g) return false;
    }
    return true;
  };
  ASSERT_TRUE(pumps_.until([&] { return all_gone(pumps_.history(), kPumps); }));
  ASSERT_TRUE(nodes_.until([&] { return all_gone(nodes_.history(), kPumps); }));
  ASSERT_TRUE(ports_.until([&] { return all_gone(ports_.history(), 1); }));
  report("stop() called -> every instance NOT_ALIVE_NO_WRITERS", ms_since(stopping));

  const auto by_mac = [](const auto& s) { return static_cast<unsigned>(s.mac); };
  expect_unregistered(pumps_, by_mac, kPumps, "PumpState");
  expect_unregistered(nodes_, by_mac, kPumps, "NodeStatus");
  expect_unregistered(
      ports_, [](const auto& s) { return std::string(dds::view(s.port)); }, 1, "PortStatus");

  // The last data: offline, stopped, outputs idle.
  for (unsigned mac = 1; mac <= kPumps; ++mac) {
    const auto* p = pumps_.latest(pump_mac(mac));
    ASSERT_NE(p, nullptr);
    EXPECT_FALSE(p->online) << mac;
    EXPECT_FALSE(p->inputs_valid) << mac;
    EXPECT_TRUE(p->outputs_idle) << mac;
    const auto* n = nodes_.latest(pump_mac(mac));
    ASSERT_NE(n, nullptr);
    EXPECT_EQ(n->state, dnbridge_NODE_STOPPED) << mac;
  }
  const auto* port = ports_.latest([](const auto&) { return true; });
  ASSERT_NE(port, nullptr);
  EXPECT_EQ(port->state, dnbridge_PORT_STOPPED);
  EXPECT_EQ(port->nodes_online, 0);

  // Every node was idled and released before the port stopped.
  EXPECT_FALSE(log_.contains(LogLevel::kWarn, "stopped before every node was released"));
}

}  // namespace
}  // namespace dnbridge::e2e
