// What a reload makes of a configuration read again: the live settings
// taken from the file, the others kept as they are in force and each named
// as needing a restart.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "adapters/daemon/reload.hpp"

namespace dnbridge::daemon {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

devicenet::MacId mac(unsigned v) { return devicenet::MacId::from(v).value(); }

constexpr Duration kDeadline = seconds(2);  // offered for publish periods up to 1 s

DaemonConfig config() { return parse_config(embedded_default_config_text(), "rack.toml"); }

TEST(ReloadPlan, TheSameFileChangesNothingAndNeedsNoRestart) {
  const auto plan = plan_reload(config(), config(), kDeadline);
  EXPECT_THAT(plan.needs_restart, IsEmpty());
  EXPECT_EQ(plan.in_force.ports.at(0).nodes.size(), 8u);
}

TEST(ReloadPlan, NodesTimingsLogLevelAndPolicyAreLive) {
  auto next = config();
  auto& port = next.ports.at(0);
  port.nodes.pop_back();
  port.nodes.at(0).pump.node.poll_period = milliseconds(250);
  port.master.poll_response_timeout = milliseconds(70);
  next.log_level = LogLevel::kDebug;
  next.explicit_policy.allow_output_writes = true;
  const auto plan = plan_reload(config(), next, kDeadline);
  EXPECT_THAT(plan.needs_restart, IsEmpty());
  const auto& in_force = plan.in_force;
  EXPECT_EQ(in_force.ports.at(0).nodes.size(), 7u);
  EXPECT_EQ(in_force.ports.at(0).nodes.at(0).pump.node.poll_period, milliseconds(250));
  EXPECT_EQ(in_force.ports.at(0).master.poll_response_timeout, milliseconds(70));
  EXPECT_EQ(in_force.log_level, LogLevel::kDebug);
  EXPECT_TRUE(in_force.explicit_policy.allow_output_writes);
}

TEST(ReloadPlan, WhatOnlyARestartChangesIsNamedAndKept) {
  auto next = config();
  next.rack = "rack-b";
  next.domain_id = 7;
  next.metrics_listen = "127.0.0.1:9810";
  auto& port = next.ports.at(0);
  port.interface = "can0";
  port.bitrate = 250000;
  port.master.master_mac = mac(1);
  port.nodes.erase(port.nodes.begin());  // MAC 1 is the new master's
  port.master_serial_number = 0x1234;
  next.ports.push_back(next.ports.at(0));
  next.ports.back().name = "B";
  const auto plan = plan_reload(config(), next, kDeadline);
  EXPECT_THAT(
      plan.needs_restart,
      ElementsAre("rack: sim-rack in force, rack-b in the file",
                  "domain: 0 in force, 7 in the file",
                  "metrics listen: off in force, 127.0.0.1:9810 in the file",
                  "port B: not in the configuration in force (a new port)",
                  "port A: interface simulated in force, can0 in the file",
                  "port A: bitrate 500000 in force, 250000 in the file",
                  "port A: master_mac 0 in force, 1 in the file",
                  "port A: master_serial_number derived from the host in force, 0x00001234 in the "
                  "file"));
  const auto& kept = plan.in_force;
  EXPECT_EQ(kept.rack, "sim-rack");
  EXPECT_EQ(kept.domain_id, 0u);
  EXPECT_FALSE(kept.metrics_listen.has_value());
  ASSERT_EQ(kept.ports.size(), 1u);
  EXPECT_EQ(kept.ports.at(0).interface, "simulated");
  EXPECT_EQ(kept.ports.at(0).bitrate, 500000u);
  EXPECT_EQ(kept.ports.at(0).master.master_mac, mac(0));
  EXPECT_FALSE(kept.ports.at(0).master_serial_number.has_value());
  // The nodes are the file's all the same.
  EXPECT_EQ(kept.ports.at(0).nodes.size(), 7u);
}

TEST(ReloadPlan, APortLeftOutRunsUntilARestart) {
  auto next = config();
  next.ports.clear();
  const auto plan = plan_reload(config(), next, kDeadline);
  EXPECT_THAT(plan.needs_restart,
              ElementsAre("port A: no longer in the file; it runs until a restart"));
  EXPECT_EQ(plan.in_force.ports.at(0).nodes.size(), 8u);
}

TEST(ReloadPlan, APublishPeriodBeyondTheOfferedDeadlineWaitsForARestart) {
  auto next = config();
  next.ports.at(0).nodes.at(2).publish.max_period = seconds(5);
  next.ports.at(0).nodes.at(3).publish.max_period = milliseconds(500);
  const auto plan = plan_reload(config(), next, kDeadline);
  ASSERT_EQ(plan.needs_restart.size(), 1u);
  EXPECT_EQ(plan.needs_restart[0],
            "port A: node 3: publish_max_period_ms 5000: the state topics were offered a "
            "deadline of 2000 ms at start; 1000 ms in force until a restart");
  EXPECT_EQ(plan.in_force.ports.at(0).nodes.at(2).publish.max_period, seconds(1));
  EXPECT_EQ(plan.in_force.ports.at(0).nodes.at(3).publish.max_period, milliseconds(500));
}

TEST(ReloadPlan, ASimulatedDeviceNowConfiguredNeedsNoRestart) {
  auto before = config();
  before.ports.at(0).simulated_unconfigured = {mac(17), mac(20)};
  auto next = before;
  next.ports.at(0).simulated_unconfigured = {mac(20)};
  next.ports.at(0).nodes.push_back(next.ports.at(0).nodes.back());
  next.ports.at(0).nodes.back().pump.node.mac = mac(17);
  EXPECT_THAT(plan_reload(before, next, kDeadline).needs_restart, IsEmpty());
  // One dropped that the file does not configure: the device stays until a
  // restart.
  next.ports.at(0).simulated_unconfigured = {};
  EXPECT_THAT(plan_reload(before, next, kDeadline).needs_restart,
              ElementsAre("port A: simulated_unconfigured [20] in force, [] in the file"));
}

TEST(ReloadPlan, APortsChangeInWords) {
  port::PortChange c;
  c.scan_list.added = {mac(9)};
  c.scan_list.removed = {mac(7), mac(8)};
  c.scan_list.reconfigured = {mac(2)};
  c.scan_list.updated = {mac(3)};
  c.scan_list.timings_changed = true;
  c.publish_changed = {mac(4)};
  c.explicit_policy_changed = true;
  EXPECT_THAT(
      describe("A", c),
      ElementsAre("port A: node 9 added", "port A: nodes 7, 8 removed: idled, then released",
                  "port A: node 2 configured again: released, idle until a new command once back "
                  "online",
                  "port A: node 3 name or policies changed: applied in place",
                  "port A: node 4 publish policy changed",
                  "port A: the port's timings changed, for every node",
                  "port A: the explicit policy changed"));
  EXPECT_THAT(describe("A", port::PortChange{}), IsEmpty());
}

}  // namespace
}  // namespace dnbridge::daemon
