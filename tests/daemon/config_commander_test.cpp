// The commander keys of the rack file: max_commander_lease_ms (the rack's)
// and command_refresh_ms (a node's own, else its port's, else [defaults]',
// else off), their ranges, and what a reload does with them.
#include <gtest/gtest.h>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/reload.hpp"
#include "config_text.hpp"

namespace dnbridge::daemon {
namespace {

using config_test::problems;

Duration refresh_of(const DaemonConfig& c, std::size_t port, std::size_t node) {
  return c.ports.at(port).nodes.at(node).pump.command_refresh;
}

TEST(ConfigCommanders, TheLeaseBoundIsTenSecondsUnlessTheRackSaysAndTheRefreshOff) {
  const DaemonConfig c = parse_config(
      "rack = \"r\"\n[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
      "[[port.node]]\nmac = 1\nname = \"p\"\n",
      "t.toml");
  EXPECT_EQ(c.max_commander_lease, seconds(10));
  EXPECT_EQ(refresh_of(c, 0, 0), Duration::zero());
  const DaemonConfig d = parse_config(
      "rack = \"r\"\nmax_commander_lease_ms = 3000\n"
      "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
      "[[port.node]]\nmac = 1\nname = \"p\"\n",
      "t.toml");
  EXPECT_EQ(d.max_commander_lease, milliseconds(3000));
}

TEST(ConfigCommanders, ARefreshIsTheNodesOwnElseItsPortsElseTheDefaults) {
  const DaemonConfig c = parse_config(
      "rack = \"r\"\n"
      "[defaults]\ncommand_refresh_ms = 2000\n"
      "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
      "command_refresh_ms = 1000\n"
      "[[port.node]]\nmac = 1\nname = \"own\"\ncommand_refresh_ms = 500\n"
      "[[port.node]]\nmac = 2\nname = \"port's\"\n"
      "[[port.node]]\nmac = 3\nname = \"off\"\ncommand_refresh_ms = 0\n"
      "[[port]]\nname = \"B\"\ninterface = \"simulated\"\nbitrate = 500000\n"
      "[[port.node]]\nmac = 1\nname = \"defaults'\"\n",
      "t.toml");
  EXPECT_EQ(refresh_of(c, 0, 0), milliseconds(500));
  EXPECT_EQ(refresh_of(c, 0, 1), milliseconds(1000));
  EXPECT_EQ(refresh_of(c, 0, 2), Duration::zero());
  EXPECT_EQ(refresh_of(c, 1, 0), milliseconds(2000));
  // The rack model gets it, for either profile.
  EXPECT_EQ(to_port_nodes(c.ports.at(0)).of<rack::PumpConfig>().at(1).command_refresh,
            milliseconds(1000));
}

TEST(ConfigCommanders, OutOfRangeValuesAreErrors) {
  EXPECT_EQ(problems("rack = \"r\"\nmax_commander_lease_ms = 50\n"
                     "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
                     "command_refresh_ms = 10\n"
                     "[[port.node]]\nmac = 1\nname = \"p\"\ncommand_refresh_ms = 700000\n"),
            "t.toml:2:26: max_commander_lease_ms = 50 is out of range (100..600000 ms)\n"
            "t.toml:7:22: command_refresh_ms = 10 is too short: use 0 (off) or 50..600000 ms\n"
            "t.toml:11:22: command_refresh_ms = 700000 is out of range (0..600000 ms)");
}

TEST(ConfigCommanders, AReloadAppliesARefreshAndNamesALeaseBoundForARestart) {
  const char* before =
      "rack = \"r\"\n[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
      "[[port.node]]\nmac = 1\nname = \"p\"\n";
  const char* after =
      "rack = \"r\"\nmax_commander_lease_ms = 5000\n"
      "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
      "[[port.node]]\nmac = 1\nname = \"p\"\ncommand_refresh_ms = 800\n";
  const ReloadPlan plan =
      plan_reload(parse_config(before, "t.toml"), parse_config(after, "t.toml"), seconds(2));
  EXPECT_EQ(plan.in_force.max_commander_lease, seconds(10));
  EXPECT_EQ(plan.in_force.ports.at(0).nodes.at(0).pump.command_refresh, milliseconds(800));
  ASSERT_EQ(plan.needs_restart.size(), 1u);
  EXPECT_EQ(plan.needs_restart[0], "max_commander_lease_ms: 10000 in force, 5000 in the file");
}

}  // namespace
}  // namespace dnbridge::daemon
