// PortReconfiguration on a fake clock: a reload applied to the rack, what
// the port keeps of each node, the instances disposed, the explicit policy,
// and a reload the master refuses changing nothing.
#include "adapters/port/port_reconfiguration.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "port/component_fixture.hpp"

namespace dnbridge::port {
namespace {

using devicenet::MacId;
using test::mac;

class PortReconfigurationTest : public ::testing::Test {
 protected:
  PortReconfigurationTest() {
    in_force.port = "can0";
    in_force.nodes = test::pumps({1, 2, 3});
    reconfiguration.start(in_force);
    publication.start(t0);
    publication.publish(port, t0, false);
    publisher.clear();
  }
  PortLoopConfig next_of(std::vector<unsigned> macs) {
    PortLoopConfig next = in_force;
    next.scanner = port.scanner().config();
    next.nodes = test::pumps(std::move(macs));
    return next;
  }

  test::NullSink sink;
  rack::RackPort port{{}, test::pumps({1, 2, 3}), sink, Logger()};
  rack::ExplicitGateway gateway{port.scanner()};
  test::CountingPublisher publisher;
  NodePublication publication{"can0", seconds(1), publisher};
  BusMetrics metrics{seconds(1)};
  PortReconfiguration reconfiguration{port, publication, metrics, publisher, Logger()};
  PortLoopConfig in_force;
  const TimePoint t0 = TimePoint{} + seconds(50);
};

TEST_F(PortReconfigurationTest, AppliesWhatDiffersAndDisposesTheNodesThatGo) {
  PortLoopConfig next = next_of({1, 2, 4});
  next.nodes.of<rack::PumpConfig>()[1].io =
      profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn118);
  next.publish[mac(1)].max_period = seconds(3);
  next.explicit_policy.allow_other_services = true;
  const PortChange change = reconfiguration.apply(in_force, next, gateway, t0);
  EXPECT_TRUE(change.refused.empty());
  EXPECT_EQ(change.scan_list.removed, std::vector<MacId>{mac(3)});
  EXPECT_EQ(change.scan_list.added, std::vector<MacId>{mac(4)});
  EXPECT_EQ(change.scan_list.reconfigured, std::vector<MacId>{mac(2)});
  EXPECT_EQ(change.publish_changed, std::vector<MacId>{mac(1)});
  EXPECT_TRUE(change.explicit_policy_changed);
  EXPECT_TRUE(gateway.policy().allow_other_services);
  // Configured again as a node of the same profile: its instances stay.
  EXPECT_EQ(publisher.removed, std::vector<unsigned>{3});
  EXPECT_EQ(in_force.nodes.size(), 3u);
  EXPECT_EQ(in_force.publish.at(mac(1)).max_period, seconds(3));

  // The nodes new or configured again are published at the next pass.
  publication.publish(port, t0 + milliseconds(1), false);
  EXPECT_EQ(publisher.statuses, (std::vector<unsigned>{2, 4}));
}

TEST_F(PortReconfigurationTest, ARefusedReloadChangesNothing) {
  PortLoopConfig next = next_of({1, 2});
  next.nodes.of<rack::PumpConfig>().push_back(test::pump(2));  // MAC 2 twice
  next.explicit_policy.allow_other_services = true;
  const PortChange change = reconfiguration.apply(in_force, next, gateway, t0);
  EXPECT_FALSE(change.refused.empty());
  EXPECT_FALSE(change.any());
  EXPECT_EQ(in_force.nodes.size(), 3u);
  EXPECT_FALSE(gateway.policy().allow_other_services);
  EXPECT_TRUE(publisher.removed.empty());
}

TEST_F(PortReconfigurationTest, AnUnchangedReloadChangesNothing) {
  PortLoopConfig next = next_of({1, 2, 3});
  const PortChange change = reconfiguration.apply(in_force, next, gateway, t0);
  EXPECT_TRUE(change.refused.empty());
  EXPECT_FALSE(change.any());
  publication.publish(port, t0 + milliseconds(1), false);
  EXPECT_TRUE(publisher.statuses.empty());
}

}  // namespace
}  // namespace dnbridge::port
