// NodePublication on a fake clock: a pass publishes the nodes the rack
// marked changed and those whose period is due, and no others; what each is
// given follows the gate and the status period; a reload's carry keeps or
// renews what was published of each node.
#include "adapters/port/node_publication.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "port/component_fixture.hpp"

namespace dnbridge::port {
namespace {

using devicenet::NodeState;
using test::mac;

class NodePublicationTest : public ::testing::Test {
 protected:
  NodePublicationTest() {
    rack::ScanListChange all;
    all.added = {mac(1), mac(2), mac(3)};
    publication.start(t0);
    publication.carry(port, all, {});
  }
  // A life-cycle event of the node at `m`, as the master reports it.
  void event(unsigned m, NodeState from, NodeState to, TimePoint at) {
    port.nodes<rack::PumpRack>().on_node_state(mac(m), from, to, "test", at);
  }

  test::NullSink sink;
  rack::RackPort port{{}, test::pumps({1, 2, 3}), sink, Logger()};
  test::CountingPublisher publisher;
  const TimePoint t0 = TimePoint{} + seconds(100);
  NodePublication publication{"can0", seconds(1), publisher};
};

TEST_F(NodePublicationTest, FirstPassPublishesEveryNodeThenNothingUntilAChangeOrAPeriod) {
  publication.publish(port, t0, false);
  EXPECT_EQ(publisher.states, (std::vector<unsigned>{1, 2, 3}));
  EXPECT_EQ(publisher.statuses, (std::vector<unsigned>{1, 2, 3}));
  // Absent since the loop started: the source time is the start.
  EXPECT_EQ(publisher.state_times[2], t0);
  EXPECT_EQ(publication.next_due(), t0 + seconds(1));

  publisher.clear();
  publication.publish(port, t0 + milliseconds(10), false);
  publication.publish(port, t0 + milliseconds(999), false);
  EXPECT_TRUE(publisher.states.empty());
  EXPECT_TRUE(publisher.statuses.empty());
}

TEST_F(NodePublicationTest, AChangedNodeAloneIsPublished) {
  publication.publish(port, t0, false);
  publisher.clear();
  event(2, NodeState::kAbsent, NodeState::kIdentifying, t0 + milliseconds(5));
  publication.publish(port, t0 + milliseconds(10), false);
  // Its status changed; its state is the same to its gate (still offline).
  EXPECT_EQ(publisher.statuses, std::vector<unsigned>{2});
  EXPECT_TRUE(publisher.states.empty());
  // Its status period starts again from then; the others' does not.
  EXPECT_EQ(publication.next_due(), t0 + seconds(1));
  publisher.clear();
  publication.publish(port, t0 + seconds(1), false);
  EXPECT_EQ(publisher.statuses, (std::vector<unsigned>{1, 3}));
  EXPECT_EQ(publisher.states, (std::vector<unsigned>{1, 2, 3}));  // the gates' maximum period
  EXPECT_EQ(publication.next_due(), t0 + milliseconds(1010));
  publisher.clear();
  publication.publish(port, t0 + milliseconds(1010), false);
  EXPECT_EQ(publisher.statuses, std::vector<unsigned>{2});
  EXPECT_TRUE(publisher.states.empty());
}

TEST_F(NodePublicationTest, ForcePublishesEveryNode) {
  publication.publish(port, t0, false);
  publisher.clear();
  publication.publish(port, t0 + milliseconds(1), true);
  EXPECT_EQ(publisher.states, (std::vector<unsigned>{1, 2, 3}));
  EXPECT_EQ(publisher.statuses, (std::vector<unsigned>{1, 2, 3}));
}

TEST_F(NodePublicationTest, NothingIsDueWithoutNodes) {
  test::NullSink none_sink;
  rack::RackPort empty({}, rack::PortNodes{}, none_sink, Logger());
  NodePublication alone("can0", seconds(1), publisher);
  alone.carry(empty, {}, {});
  alone.publish(empty, t0, false);
  EXPECT_EQ(alone.next_due(), kNever);
  EXPECT_TRUE(publisher.statuses.empty());
}

TEST_F(NodePublicationTest, CarryKeepsKeptNodesRenewsNewOnesAndDropsRemovedOnes) {
  publication.publish(port, t0, false);
  publisher.clear();
  // MAC 3 goes, MAC 4 comes, MAC 2 gets another publish policy.
  const TimePoint t1 = t0 + milliseconds(100);
  const rack::ScanListChange sc =
      port.reconfigure(port.scanner().config(), test::pumps({1, 2, 4}), t1);
  NodePublication::Policies policies;
  policies[mac(2)].max_period = seconds(5);
  const auto carried = publication.carry(port, sc, policies);
  EXPECT_EQ(carried.fresh, std::vector<devicenet::MacId>{mac(4)});
  EXPECT_EQ(carried.policy_changed, std::vector<devicenet::MacId>{mac(2)});
  publication.publish(port, t1, false);
  // The new node at once, and MAC 2's state by its new gate; MAC 1 as
  // before (MAC 3's mark is dropped).
  EXPECT_EQ(publisher.states, (std::vector<unsigned>{2, 4}));
  EXPECT_EQ(publisher.statuses, std::vector<unsigned>{4});
  publisher.clear();
  publication.publish(port, t0 + seconds(1), false);
  // MAC 2's new gate is next due in 5 s; MAC 1's period is due.
  EXPECT_EQ(publisher.states, std::vector<unsigned>{1});
  EXPECT_EQ(publisher.statuses, (std::vector<unsigned>{1, 2}));
}

}  // namespace
}  // namespace dnbridge::port
