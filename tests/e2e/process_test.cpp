// The dnbridge executable itself, in a process of its own: the supervisor
// reaches it across processes over loopback (in-process participants share
// Cyclone's domain and never touch the network), and SIGTERM stops it in
// order. Its configuration is the embedded default on this process's domain;
// CYCLONEDDS_URI (loopback, this process's discovery tag) is inherited.
#include <filesystem>
#include <map>

#include "bridge_fixture.hpp"
#include "bridge_process.hpp"
#include "child_process.hpp"

namespace dnbridge::e2e {
namespace {

TEST_F(BridgeTest, DnbridgeProcessServesTheSupervisorAndStopsInOrderOnSigterm) {
  const auto config = write_simulated_rack_config(test_domain());
  const auto spawned = SteadyClock::now();
  ChildProcess bridge({DNBRIDGE_BINARY, "--config", config.string()});
  ASSERT_TRUE(bridge.running());

  ASSERT_TRUE(pumps_.matched(1));
  report("dnbridge process spawned -> its PumpState writer discovered", ms_since(spawned));
  auto seen = [&] {
    for (unsigned mac = 1; mac <= kPumps; ++mac) {
      if (!pumps_.latest(pump_mac(mac))) return false;
    }
    return true;
  };
  const auto discovered = SteadyClock::now();
  ASSERT_TRUE(pumps_.until(seen, seconds(1))) << "not every pump within one publish period";
  report("dnbridge process: writer discovered -> every pump's PumpState", ms_since(discovered));
  ASSERT_TRUE(pumps_.until([&] { return all_online(); }, seconds(10)));
  report("dnbridge process spawned -> every pump online", ms_since(spawned));
  EXPECT_EQ(writer_participant_name(supervisor_, pumps_.reader()), std::string("dnbridge ") + kRack);

  ASSERT_TRUE(bridge.signal(SIGTERM));
  auto unregistered = [&] {
    std::map<unsigned, bool> gone;
    for (const auto& r : pumps_.history()) {
      gone[r.sample->mac] =
          r.sample.info().instance_state() == dds::InstanceState::kNotAliveNoWriters;
    }
    if (gone.size() != kPumps) return false;
    for (const auto& [mac, g] : gone) {
      if (!g) return false;
    }
    return true;
  };
  ASSERT_TRUE(pumps_.until(unregistered));
  for (const auto& r : pumps_.history()) {
    EXPECT_NE(r.sample.info().instance_state(), dds::InstanceState::kNotAliveDisposed);
  }
  for (unsigned mac = 1; mac <= kPumps; ++mac) {
    EXPECT_FALSE(pumps_.latest(pump_mac(mac))->online) << mac;
  }
  EXPECT_EQ(bridge.wait(), 0);
  std::filesystem::remove(config);
}

}  // namespace
}  // namespace dnbridge::e2e
