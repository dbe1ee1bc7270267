// Which nodes a rack marks changed (ProfileNodes::take_changed): every node
// whose view a master's event, a command or a reload changes, each once
// until taken; nothing for a MAC not in the rack.
#include <gtest/gtest.h>

#include <vector>

#include "bridge/profiles/cdn127/poll_format.hpp"
#include "bridge/rack/pump_rack.hpp"
#include "bridge/rack/rack_port.hpp"

namespace dnbridge::rack {
namespace {

using devicenet::MacId;
using devicenet::NodeState;

MacId mac(unsigned m) { return *MacId::from(m); }
std::uint64_t bit(unsigned m) { return std::uint64_t{1} << m; }

PumpConfig pump(unsigned m) {
  PumpConfig p;
  p.node.mac = mac(m);
  p.node.name = "pump " + std::to_string(m);
  p.io = profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn127);
  return p;
}

class NullSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame&, TimePoint) override {}
};

TEST(ChangedNodes, EveryNodeAddedThenOnlyTheOnesChanged) {
  NullSink sink;
  RackPort port({}, PortNodes(std::vector<PumpConfig>{pump(1), pump(9)}), sink, Logger());
  EXPECT_EQ(port.take_changed(), bit(1) | bit(9));
  EXPECT_EQ(port.take_changed(), 0u);

  PumpRack& pumps = port.nodes<PumpRack>();
  const TimePoint now{};
  pumps.on_node_state(mac(9), NodeState::kAbsent, NodeState::kIdentifying, "test", now);
  pumps.on_device_state(mac(9), 3, now);
  EXPECT_EQ(port.take_changed(), bit(9));
  // A MAC the rack does not have.
  pumps.on_node_state(mac(20), NodeState::kAbsent, NodeState::kIdentifying, "test", now);
  EXPECT_EQ(port.take_changed(), 0u);
  // A command refused (the node is not online) changes the view's counts.
  const auto before = pumps.node(mac(1))->status_changes;
  EXPECT_FALSE(pumps.command(mac(1), profiles::cdn127::PumpOutputs{}, "tester", now));
  EXPECT_NE(pumps.node(mac(1))->status_changes, before);
  EXPECT_EQ(port.take_changed(), bit(1));
}

TEST(ChangedNodes, AReloadMarksTheNodesItChanges) {
  NullSink sink;
  RackPort port({}, PortNodes(std::vector<PumpConfig>{pump(1), pump(2), pump(3)}), sink, Logger());
  (void)port.take_changed();
  std::vector<PumpConfig> next{pump(1), pump(2), pump(4)};
  next[0].node.name = "renamed";  // handled otherwise, in place
  next[1].io = profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn118);
  const ScanListChange c = port.reconfigure(port.scanner().config(), PortNodes(next), TimePoint{});
  ASSERT_EQ(c.updated, std::vector<MacId>{mac(1)});
  ASSERT_EQ(c.reconfigured, std::vector<MacId>{mac(2)});
  // MAC 3 left: nothing of it to look at.
  EXPECT_EQ(port.take_changed(), bit(1) | bit(2) | bit(4));
}

}  // namespace
}  // namespace dnbridge::rack
