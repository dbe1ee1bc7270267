// What a supervisor sees of a bridge that starts: every pump at once, then
// online; samples stamped with their CAN receive time on the wall clock; the
// bridge's participant named after its rack; the port's status measured; a
// late joiner served the current state from the bridge's history.
#include <map>
#include <set>

#include "bridge_fixture.hpp"

namespace dnbridge::e2e {
namespace {

TEST_F(BridgeTest, EveryPumpIsSeenWithinOnePublishPeriodOfStartUp) {
  const auto config = rack_config();
  const Duration publish_period = config.ports[0].nodes[0].publish.max_period;
  ASSERT_NO_FATAL_FAILURE(make_bridge(config));
  start_bridge();

  auto seen = [&] {
    for (unsigned mac = 1; mac <= kPumps; ++mac) {
      if (!pumps_.latest(pump_mac(mac))) return false;
    }
    return true;
  };
  ASSERT_TRUE(pumps_.until(seen, publish_period)) << "not every pump within one publish period";
  report("every pump's first PumpState after start()", ms_since(started_));
  for (unsigned mac = 1; mac <= kPumps; ++mac) {
    const auto* s = pumps_.latest(pump_mac(mac));
    EXPECT_EQ(dds::view(s->rack), kRack);
    EXPECT_EQ(dds::view(s->port), kPort);
    EXPECT_EQ(dds::view(s->name), "pump-" + std::to_string(mac));
  }

  ASSERT_TRUE(pumps_.until([&] { return all_online(); }, seconds(10)));
  report("every pump online after start()", ms_since(started_));
  ASSERT_TRUE(nodes_.until([&] {
    for (unsigned mac = 1; mac <= kPumps; ++mac) {
      const auto* n = nodes_.latest(pump_mac(mac));
      if (!n || n->state != dnbridge_NODE_ONLINE) return false;
    }
    return true;
  }));
  for (unsigned mac = 1; mac <= kPumps; ++mac) {
    const auto* n = nodes_.latest(pump_mac(mac));
    EXPECT_EQ(dds::view(n->product_name), "CDN127");
    EXPECT_EQ(n->vendor_id, 59);
    // Read with the explicit connection's keep-alive (every 2.5 s).
    if (n->device_state_valid) {
      EXPECT_EQ(n->device_state, 3);  // operating
    }
  }
  // Analog input values and inputs: what the simulated CDN127 reads.
  const auto* pump1 = pumps_.latest(pump_mac(1));
  EXPECT_TRUE(pump1->inputs_valid);
  EXPECT_TRUE(pump1->interlock_ok);
  EXPECT_EQ(pump1->analog_input_count, 2);
  EXPECT_EQ(pumps_.latest(pump_mac(8))->analog_input_count, 0);  // cdn118: no analog inputs
}

TEST_F(BridgeTest, SourceTimestampsAreReceiveTimesOnTheWallClockAndIncrease) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  // One more publish period (and a little): periodic samples of every pump.
  const auto until = SteadyClock::now() + milliseconds(1200);
  pumps_.until([&] { return SteadyClock::now() >= until; }, seconds(2));
  nodes_.take_all();
  ports_.take_all();

  std::map<unsigned, std::vector<dds::Timestamp>> per_pump;
  std::map<unsigned, std::vector<dds::Timestamp>> polled;  // samples with inputs
  for (const auto& r : pumps_.history()) {
    if (!r.sample.valid_data()) continue;
    const auto t = r.sample.info().source_timestamp();
    // Written after the bridge was built, received after it was written.
    EXPECT_GE(t, created_wall_) << "mac " << int(r.sample->mac) << ": "
                                << std::chrono::duration<double>(created_wall_ - t).count()
                                << " s before the bridge existed";
    EXPECT_LE(t, r.at) << "mac " << int(r.sample->mac);
    per_pump[r.sample->mac].push_back(t);
    if (r.sample->inputs_valid) polled[r.sample->mac].push_back(t);
  }
  ASSERT_EQ(per_pump.size(), kPumps);
  for (const auto& [mac, times] : per_pump) {
    ASSERT_GE(times.size(), 3u) << "mac " << mac;
    for (std::size_t i = 1; i < times.size(); ++i) {
      EXPECT_GE(times[i], times[i - 1]) << "mac " << mac << " sample " << i;
    }
    EXPECT_GT(times.back(), times.front()) << "mac " << mac;
  }
  // Nothing but polls happens here: each sample with inputs carries a newer
  // poll response (a republished unchanged state keeps its event's time).
  for (const auto& [mac, times] : polled) {
    ASSERT_GE(times.size(), 2u) << "mac " << mac;
    for (std::size_t i = 1; i < times.size(); ++i) {
      EXPECT_GT(times[i], times[i - 1]) << "mac " << mac << " polled sample " << i;
    }
  }
  for (const auto& r : nodes_.history()) {
    if (!r.sample.valid_data()) continue;
    EXPECT_GE(r.sample.info().source_timestamp(), created_wall_)
        << "NodeStatus " << int(r.sample->mac);
    EXPECT_LE(r.sample.info().source_timestamp(), r.at);
  }
  for (const auto& r : ports_.history()) {
    if (!r.sample.valid_data()) continue;
    EXPECT_GE(r.sample.info().source_timestamp(), created_wall_) << "PortStatus";
    EXPECT_LE(r.sample.info().source_timestamp(), r.at);
  }
}

TEST_F(BridgeTest, ParticipantIsNamedAfterTheRack) {
  ASSERT_NO_FATAL_FAILURE(make_bridge());
  EXPECT_EQ(writer_participant_name(supervisor_, pumps_.reader()),
            std::string("dnbridge ") + kRack);
}

TEST_F(BridgeTest, PortStatusShowsMeasuredScanCycleAndALateJoinerGetsTheCurrentStateAtOnce) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  // The scan cycle is measured over whole status periods with every node
  // polled: the first one that ends after every node is online.
  auto measured = [&] {
    const auto* p = ports_.latest([](const auto& s) { return dds::view(s.port) == kPort; });
    return p && p->state == dnbridge_PORT_RUNNING && p->nodes_online == kPumps &&
           p->scan_cycle_ms > 0;
  };
  ASSERT_TRUE(ports_.until(measured, seconds(4)));
  const auto* p = ports_.latest([](const auto& s) { return dds::view(s.port) == kPort; });
  report("PortStatus with a measured scan cycle after start()", ms_since(started_));
  report("measured scan cycle (poll period 100 ms)", p->scan_cycle_ms);
  EXPECT_EQ(dds::view(p->rack), kRack);
  EXPECT_EQ(dds::view(p->can_interface), "simulated");
  EXPECT_EQ(p->bitrate, 500000u);
  EXPECT_EQ(p->master_mac, 0);
  EXPECT_EQ(p->nodes_configured, kPumps);
  EXPECT_EQ(p->bus_state, dnbridge_BUS_ERROR_ACTIVE);
  // Polled every 100 ms (embedded default poll_period_ms).
  EXPECT_GT(p->scan_cycle_ms, 80.0f);
  EXPECT_LT(p->scan_cycle_ms, 150.0f);
  EXPECT_GT(p->frames_per_second, 0.0f);
  EXPECT_GT(p->bus_load_percent, 0.0f);
  EXPECT_LT(p->bus_load_percent, 100.0f);

  // A supervisor that starts now, in a participant (process) of its own.
  dds::Participant late(test_domain(), "late supervisor");
  dds::Topic<dnbridge_PumpState> pump_topic(late);
  dds::Topic<dnbridge_PortStatus> port_topic(late);
  const auto joined = SteadyClock::now();
  const auto joined_wall = wall_now();
  Subscription<dnbridge_PumpState> late_pumps(late, pump_topic, dds::state_reader_qos());
  Subscription<dnbridge_PortStatus> late_ports(late, port_topic, dds::state_reader_qos());
  auto all = [&] {
    for (unsigned mac = 1; mac <= kPumps; ++mac) {
      if (!late_pumps.latest(pump_mac(mac))) return false;
    }
    return true;
  };
  ASSERT_TRUE(late_pumps.until(all));
  ASSERT_TRUE(
      late_ports.until([&] { return late_ports.latest([](const auto&) { return true; }); }));
  report("late joiner: every pump's state and the port's after creating the readers",
         ms_since(joined));
  // The first sample of each instance is the one the bridge had already
  // written (from its history, not a later publish): stamped before the
  // reader existed, and the current state.
  std::set<unsigned> first;
  for (const auto& r : late_pumps.history()) {
    ASSERT_TRUE(r.sample.valid_data());
    if (!first.insert(r.sample->mac).second) continue;
    EXPECT_LT(r.sample.info().source_timestamp(), joined_wall) << "mac " << int(r.sample->mac);
    EXPECT_TRUE(r.sample->online) << "mac " << int(r.sample->mac);
    EXPECT_TRUE(r.sample->inputs_valid) << "mac " << int(r.sample->mac);
  }
  EXPECT_EQ(first.size(), kPumps);
  const auto& port_first = late_ports.history().front();
  EXPECT_LT(port_first.sample.info().source_timestamp(), joined_wall);
  EXPECT_EQ(port_first.sample->state, dnbridge_PORT_RUNNING);
  EXPECT_EQ(port_first.sample->nodes_online, kPumps);
  EXPECT_GT(port_first.sample->scan_cycle_ms, 0.0f);
}

}  // namespace
}  // namespace dnbridge::e2e
