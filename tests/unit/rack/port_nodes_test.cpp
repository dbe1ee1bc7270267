// A port's scan list of nodes of any profile (PortNodes), and the port
// (RackPort) that makes one rack per profile from it: the racks hear the
// master's events before any observer, also a rack first made by a reload.
#include "bridge/rack/port_nodes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <vector>

#include "bridge/profiles/cdn127/poll_format.hpp"
#include "bridge/rack/device_rack.hpp"
#include "bridge/rack/pump_rack.hpp"
#include "bridge/rack/rack_port.hpp"
#include "support/example_eds.hpp"

namespace dnbridge::rack {
namespace {

using devicenet::MacId;
using devicenet::NodeState;

MacId mac(unsigned m) { return *MacId::from(m); }

PumpConfig pump(unsigned m) {
  PumpConfig p;
  p.node.mac = mac(m);
  p.node.name = "pump " + std::to_string(m);
  p.io = profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn127);
  return p;
}

DeviceConfig io_block(unsigned m) {
  DeviceConfig d;
  d.node.mac = mac(m);
  d.node.name = "io " + std::to_string(m);
  d.eds = std::make_shared<const profiles::eds::EdsFile>(test::example_eds(test::kIoBlockEds));
  d.eds_path = test::kIoBlockEds;
  d.settings.safe_state_of_device = true;
  return d;
}

class NullSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame&, TimePoint) override {}
};

// At each node's state change, the node's rack already has it.
class AfterTheRacks final : public devicenet::ScannerObserver {
 public:
  explicit AfterTheRacks(const RackPort& port) : port_(port) {}
  void on_node_state(MacId m, NodeState, NodeState to, const std::string&, TimePoint) override {
    const ProfileNodes* nodes = port_.nodes_of(m);
    ASSERT_NE(nodes, nullptr) << m.value();
    EXPECT_EQ(nodes->node(m)->state, to) << m.value();
    seen.push_back(m);
  }
  std::vector<MacId> seen;

 private:
  const RackPort& port_;
};

// The master's timers run until `done` or a minute of fake time.
template <class Done>
void run_until(devicenet::Scanner& scanner, TimePoint& now, Done done) {
  const TimePoint end = now + seconds(60);
  while (!done() && now < end) {
    now = std::max(now, std::min(scanner.next_deadline(), end));
    scanner.on_timer(now);
  }
}

TEST(PortNodes, KeepsOneListPerProfileInTheOrderGivenAndCopiesThem) {
  PortNodes nodes(std::vector<DeviceConfig>{io_block(20)}, std::vector<PumpConfig>{pump(1)});
  ASSERT_EQ(nodes.lists().size(), 2u);
  EXPECT_EQ(nodes.lists()[0]->type(), typeid(DeviceConfig));
  EXPECT_EQ(nodes.lists()[1]->type(), typeid(PumpConfig));
  nodes.of<PumpConfig>().push_back(pump(2));
  EXPECT_EQ(nodes.size(), 3u);
  const PortNodes::At at = nodes.at(mac(2));
  ASSERT_TRUE(at);
  EXPECT_EQ(at.list, nodes.lists()[1].get());
  EXPECT_EQ(at.index, 1u);
  EXPECT_FALSE(nodes.at(mac(3)));

  PortNodes copy = nodes;
  copy.of<PumpConfig>().clear();
  EXPECT_EQ(nodes.of<PumpConfig>().size(), 2u);
  EXPECT_TRUE(copy.of<PumpConfig>().empty());
  // A profile the port has no list of: none.
  const PortNodes none;
  EXPECT_TRUE(none.of<DeviceConfig>().empty());
  EXPECT_TRUE(none.lists().empty());
}

TEST(PortNodes, ANodeOfAnotherProfileHasOtherDeviceSettings) {
  const PortNodes before(std::vector<PumpConfig>{pump(1), pump(2)});
  PortNodes after(std::vector<PumpConfig>{pump(1)}, std::vector<DeviceConfig>{io_block(2)});
  after.of<PumpConfig>()[0].node.name = "renamed";
  const devicenet::ScannerConfig port;
  const ScanListChange c = compare(port, before, port, after);
  EXPECT_EQ(c.reconfigured, std::vector<MacId>{mac(2)});
  EXPECT_EQ(c.updated, std::vector<MacId>{mac(1)});
  EXPECT_TRUE(c.added.empty());
  EXPECT_TRUE(c.removed.empty());
}

TEST(RackPort, MakesARackPerProfileAndOneAReloadFirstBrings) {
  NullSink sink;
  RackPort port({}, PortNodes(std::vector<PumpConfig>{pump(1), pump(2)}), sink, Logger());
  AfterTheRacks observer(port);
  port.observe(observer);
  ASSERT_EQ(port.profiles().size(), 1u);
  EXPECT_EQ(port.nodes<PumpRack>().size(), 2u);
  EXPECT_THROW((void)port.nodes<DeviceRack>(), std::logic_error);

  TimePoint now{};
  port.scanner().start(now);
  run_until(port.scanner(), now, [&] { return observer.seen.size() >= 2; });
  ASSERT_GE(observer.seen.size(), 2u);

  // MAC 2 becomes a device described by its EDS, MAC 30 one more: the
  // port's first of that profile, so its rack is made now, and hears the
  // master before the observer as the others do.
  const PortNodes next(std::vector<PumpConfig>{pump(1)},
                       std::vector<DeviceConfig>{io_block(2), io_block(30)});
  observer.seen.clear();
  const ScanListChange c = port.reconfigure(port.scanner().config(), next, now);
  EXPECT_EQ(c.reconfigured, std::vector<MacId>{mac(2)});
  EXPECT_EQ(c.added, std::vector<MacId>{mac(30)});
  ASSERT_EQ(port.profiles().size(), 2u);
  EXPECT_EQ(port.profiles()[1]->profile(), DeviceProfile::kName);
  EXPECT_EQ(port.nodes<PumpRack>().pump(mac(2)), nullptr);
  ASSERT_NE(port.nodes<DeviceRack>().device(mac(2)), nullptr);
  EXPECT_EQ(port.nodes_of(mac(30)), port.profiles()[1]);
  // MAC 2 left the scan list and came back in it, MAC 30 came; each
  // change seen by its new rack first.
  EXPECT_EQ(std::count(observer.seen.begin(), observer.seen.end(), mac(2)), 2);
  EXPECT_EQ(std::count(observer.seen.begin(), observer.seen.end(), mac(30)), 1);
}

}  // namespace
}  // namespace dnbridge::rack
