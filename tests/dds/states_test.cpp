#include "adapters/dds/states.hpp"

#include <gtest/gtest.h>

#include <set>

namespace dnbridge::dds {
namespace {

using devicenet::NodeState;
using devicenet::PortState;
using port::BusState;

TEST(States, EveryNodeStateHasItsOwnIdlValueAndComesBack) {
  std::set<int> seen;
  for (int i = 0; i <= static_cast<int>(NodeState::kDeviceFault); ++i) {
    const auto state = static_cast<NodeState>(i);
    const auto idl = to_idl(state);
    EXPECT_TRUE(seen.insert(static_cast<int>(idl)).second) << devicenet::to_string(state);
    EXPECT_EQ(from_idl(idl), state);
    EXPECT_EQ(name_of(idl), devicenet::to_string(state));
  }
  EXPECT_EQ(name_of(dnbridge_NODE_OWNED_BY_OTHER_MASTER), "owned by another master");
  EXPECT_EQ(from_idl(static_cast<dnbridge_NodeLifecycle>(15)), std::nullopt);
  EXPECT_EQ(name_of(static_cast<dnbridge_NodeLifecycle>(15)), "unknown");
}

TEST(States, EveryPortStateHasItsOwnIdlValueAndComesBack) {
  std::set<int> seen;
  for (int i = 0; i <= static_cast<int>(PortState::kDuplicateMac); ++i) {
    const auto state = static_cast<PortState>(i);
    const auto idl = to_idl(state);
    EXPECT_TRUE(seen.insert(static_cast<int>(idl)).second) << devicenet::to_string(state);
    EXPECT_EQ(from_idl(idl), state);
    EXPECT_EQ(name_of(idl), devicenet::to_string(state));
  }
  EXPECT_EQ(name_of(static_cast<dnbridge_PortLifecycle>(7)), "unknown");
}

TEST(States, EveryBusStateHasItsOwnIdlValueAndComesBack) {
  std::set<int> seen;
  for (int i = 0; i <= static_cast<int>(BusState::kDown); ++i) {
    const auto state = static_cast<BusState>(i);
    const auto idl = to_idl(state);
    EXPECT_TRUE(seen.insert(static_cast<int>(idl)).second) << port::to_string(state);
    EXPECT_EQ(from_idl(idl), state);
    EXPECT_EQ(name_of(idl), port::to_string(state));
  }
  EXPECT_EQ(name_of(dnbridge_BUS_OFF), "bus-off");
  EXPECT_EQ(name_of(static_cast<dnbridge_BusState>(7)), "unknown");
}

TEST(States, SafeActionsHaveTheCoresNames) {
  namespace cdn127 = profiles::cdn127;
  for (auto a :
       {cdn127::DiscreteAction::kOff, cdn127::DiscreteAction::kOn, cdn127::DiscreteAction::kHold}) {
    EXPECT_EQ(name_of(to_idl(a)), cdn127::to_string(a));
  }
  using Kind = cdn127::AnalogAction::Kind;
  EXPECT_EQ(to_idl(cdn127::AnalogAction{Kind::kLowLimit, 0}), dnbridge_SAFE_ACTION_OFF);
  EXPECT_EQ(to_idl(cdn127::AnalogAction{Kind::kHighLimit, 0}), dnbridge_SAFE_ACTION_ON);
  EXPECT_EQ(to_idl(cdn127::AnalogAction{Kind::kHold, 0}), dnbridge_SAFE_ACTION_HOLD);
  EXPECT_EQ(to_idl(cdn127::AnalogAction{Kind::kValue, 2048}), dnbridge_SAFE_ACTION_VALUE);
  EXPECT_EQ(name_of(dnbridge_SAFE_ACTION_VALUE), "value");
  EXPECT_EQ(name_of(dnbridge_SAFE_ACTION_UNKNOWN), "unknown");
}

}  // namespace
}  // namespace dnbridge::dds
