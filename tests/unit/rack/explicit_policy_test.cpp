#include "bridge/rack/explicit_policy.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <vector>

#include "bridge/profiles/cdn127/node_profile.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::rack {
namespace {

namespace cdn127 = profiles::cdn127;
using devicenet::RequestMessage;

// The settings of a CDN127 node as the bridge configures it, plus a DOP
// fault action: the policy must take whatever the profile lists.
// The CDN127 profile's settings: the Configuration object and the outputs'
// safe state (DOP 1 FaultAction among them).
std::vector<devicenet::AttributeSetting> managed_settings() {
  auto profile = cdn127::make_node_profile(cdn127::preset(cdn127::ConfigurationPreset::kCdn127),
                                           cdn127::SafeStateConfig{});
  EXPECT_TRUE(profile.ok());
  return profile->settings;
}

struct Fixture {
  std::vector<devicenet::AttributeSetting> settings = managed_settings();
  std::deque<std::vector<std::uint8_t>> data;  // what the requests' spans point into

  PolicyNode node() const { return {settings}; }
  RequestMessage request(std::uint8_t service, std::uint16_t cls, std::uint16_t instance,
                         std::optional<std::uint8_t> attribute, std::vector<std::uint8_t> d = {}) {
    data.push_back(std::move(d));
    RequestMessage r;
    r.service = service;
    r.class_id = cls;
    r.instance_id = instance;
    r.attribute = attribute;
    r.data = Bytes(data.back());
    return r;
  }
};

ExplicitPolicy allowing(GuardedRequest kind) {
  ExplicitPolicy p;
  p.allow(kind, true);
  return p;
}

ExplicitPolicy allowing_all_but(GuardedRequest kind) {
  ExplicitPolicy p{true, true, true, true, true};
  p.allow(kind, false);
  return p;
}

struct Case {
  const char* name;
  std::uint8_t service;
  std::uint16_t class_id;
  std::uint16_t instance_id;
  std::optional<std::uint8_t> attribute;
  std::vector<std::uint8_t> data;
  GuardedRequest kind;
  const char* what;  // in the message
};

// Every guarded request class, as a requester would write it.
const std::vector<Case>& guarded_cases() {
  static const std::vector<Case> cases{
      {"Allocate",
       0x4B,
       0x03,
       1,
       {},
       {0x03, 0},
       GuardedRequest::kAllocateRelease,
       "Allocate_Master/Slave_Connection_Set (0x4B) to the DeviceNet object"},
      {"Release",
       0x4C,
       0x03,
       1,
       {},
       {0x03},
       GuardedRequest::kAllocateRelease,
       "Release_Master/Slave_Connection_Set (0x4C) to the DeviceNet object"},
      {"SetPollEpr",
       0x10,
       0x05,
       2,
       9,
       {0x00, 0x00},
       GuardedRequest::kConnectionChange,
       "Set_Attribute_Single (0x10) of Connection instance 2 attribute 9"},
      {"SetExplicitWatchdog",
       0x10,
       0x05,
       1,
       12,
       {0x01},
       GuardedRequest::kConnectionChange,
       "of Connection instance 1 attribute 12"},
      {"SetAllConnection",
       0x02,
       0x05,
       2,
       {},
       {},
       GuardedRequest::kConnectionChange,
       "Set_Attributes_All (0x02) to Connection instance 2"},
      {"DeleteConnection",
       0x09,
       0x05,
       2,
       {},
       {},
       GuardedRequest::kConnectionChange,
       "Delete (0x09) to Connection instance 2"},
      {"SetDopValue",
       0x10,
       0x09,
       1,
       3,
       {0x01},
       GuardedRequest::kOutputWrite,
       "Set_Attribute_Single (0x10) of Discrete Output Point instance 1 Value"},
      {"SetAopValue",
       0x10,
       0x0B,
       1,
       3,
       {0xFF, 0x0F},
       GuardedRequest::kOutputWrite,
       "of Analog Output Point instance 1 Value"},
      {"SetAssemblyData",
       0x10,
       0x04,
       100,
       3,
       {0x01, 0x00},
       GuardedRequest::kOutputWrite,
       "of Assembly instance 100 data"},
      {"SetAllAssembly",
       0x02,
       0x04,
       100,
       {},
       {0x01, 0x00},
       GuardedRequest::kOutputWrite,
       "Set_Attributes_All (0x02) of Assembly instance 100 data"},
      {"SetConfigurationMode",
       0x10,
       0x40,
       1,
       1,
       {0x81},
       GuardedRequest::kManagedAttributeWrite,
       "Set_Attribute_Single (0x10) of Configuration.Mode"},
      {"SetDopFaultAction",
       0x10,
       0x09,
       1,
       5,
       {0x01},
       GuardedRequest::kManagedAttributeWrite,
       "of DOP 1 (pump).FaultAction"},
      {"ResetConfiguration",
       0x05,
       0x40,
       1,
       {},
       {0x01},
       GuardedRequest::kManagedAttributeWrite,
       "Reset (0x05) of class 0x40 instance 1 (Configuration.Mode and 5 more)"},
      {"ResetIdentity",
       0x05,
       0x01,
       1,
       {},
       {},
       GuardedRequest::kIdentityReset,
       "Reset (0x05) of the Identity object"},
      {"ResetIdentityOutOfBox",
       0x05,
       0x01,
       1,
       {},
       {0x01},
       GuardedRequest::kIdentityReset,
       "Reset (0x05) of the Identity object"},
      {"ResetPollConnection",
       0x05,
       0x05,
       2,
       {},
       {},
       GuardedRequest::kConnectionChange,
       "Reset (0x05) to Connection instance 2"},
      {"SetMacId",
       0x10,
       0x03,
       1,
       1,
       {0x05},
       GuardedRequest::kNetworkSettings,
       "Set_Attribute_Single (0x10) of DeviceNet object attribute 1"},
      {"SetBitRate",
       0x10,
       0x03,
       1,
       2,
       {0x02},
       GuardedRequest::kNetworkSettings,
       "Set_Attribute_Single (0x10) of DeviceNet object attribute 2"},
      {"MultipleServicePacket",
       0x0A,
       0x02,
       1,
       {},
       {0x01, 0x00, 0x04, 0x00, 0x10, 0x09, 0x01, 0x03},
       GuardedRequest::kOtherService,
       "to class 0x02 instance 1"},
      {"VendorService",
       0x32,
       0x40,
       1,
       {},
       {},
       GuardedRequest::kOtherService,
       "service 0x32 to class 0x40 instance 1"},
  };
  return cases;
}

class GuardedClass : public ::testing::TestWithParam<Case> {};

TEST_P(GuardedClass, RefusedByDefaultWithItsClassReasonAndKey) {
  const Case& c = GetParam();
  Fixture f;
  const auto r =
      check(ExplicitPolicy{}, f.request(c.service, c.class_id, c.instance_id, c.attribute, c.data),
            f.node());
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->kind, c.kind);
  EXPECT_NE(r->message.find(c.what), std::string::npos) << r->message;
  EXPECT_NE(r->message.find(name_of(c.kind)), std::string::npos) << r->message;
  EXPECT_NE(r->message.find(risk_of(c.kind)), std::string::npos) << r->message;
  EXPECT_NE(r->message.find(fmt::format("{} = true in [explicit_policy]", policy_key(c.kind))),
            std::string::npos)
      << r->message;
}

TEST_P(GuardedClass, AllowedByItsOwnKeyAndByNoOther) {
  const Case& c = GetParam();
  Fixture f;
  const auto request = f.request(c.service, c.class_id, c.instance_id, c.attribute, c.data);
  EXPECT_FALSE(check(allowing(c.kind), request, f.node()).has_value());
  const auto others = check(allowing_all_but(c.kind), request, f.node());
  ASSERT_TRUE(others.has_value());
  EXPECT_EQ(others->kind, c.kind);
}

INSTANTIATE_TEST_SUITE_P(Policy, GuardedClass, ::testing::ValuesIn(guarded_cases()),
                         [](const auto& param) { return std::string(param.param.name); });

TEST(ExplicitPolicy, GetsAreAlwaysAllowed) {
  Fixture f;
  const std::vector<std::pair<std::uint16_t, std::uint8_t>> targets{
      {0x01, 7}, {0x03, 5}, {0x04, 3}, {0x05, 9}, {0x09, 3}, {0x0B, 3}, {0x40, 1}};
  for (const auto& [cls, attr] : targets) {
    EXPECT_TRUE(classify(f.request(0x0E, cls, 1, attr), f.node()).empty()) << cls;
    EXPECT_TRUE(classify(f.request(0x01, cls, 1, {}), f.node()).empty()) << cls;
    EXPECT_FALSE(check(ExplicitPolicy{}, f.request(0x0E, cls, 1, attr), f.node()));
  }
}

TEST(ExplicitPolicy, ManagedMeansListedInTheProfile) {
  Fixture f;
  // Configuration attribute 16 (NumberProduced) is not one the bridge sets.
  EXPECT_FALSE(check(ExplicitPolicy{}, f.request(0x10, 0x40, 1, 16, {4}), f.node()));
  // Another instance of a managed attribute's class.
  EXPECT_FALSE(check(ExplicitPolicy{}, f.request(0x10, 0x40, 2, 1, {0x81}), f.node()));
  f.settings.clear();
  EXPECT_FALSE(check(ExplicitPolicy{}, f.request(0x10, 0x40, 1, 1, {0x81}), f.node()));
  EXPECT_FALSE(check(ExplicitPolicy{}, f.request(0x10, 0x09, 1, 5, {1}), f.node()));
}

TEST(ExplicitPolicy, TheAttributeIsReadAsTheDeviceReadsIt) {
  Fixture f;
  // No attribute given: the first data byte is the attribute on the wire.
  const auto dop = check(ExplicitPolicy{}, f.request(0x10, 0x09, 1, {}, {3, 1}), f.node());
  ASSERT_TRUE(dop.has_value());
  EXPECT_EQ(dop->kind, GuardedRequest::kOutputWrite);
  const auto mode = check(ExplicitPolicy{}, f.request(0x10, 0x40, 1, {}, {1, 0x81}), f.node());
  ASSERT_TRUE(mode.has_value());
  EXPECT_EQ(mode->kind, GuardedRequest::kManagedAttributeWrite);
  // A Set with no attribute at all writes nothing: the device refuses it.
  EXPECT_FALSE(check(ExplicitPolicy{}, f.request(0x10, 0x09, 1, {}), f.node()));
}

TEST(ExplicitPolicy, OtherRequestsAreNotGuarded) {
  Fixture f;
  for (const auto& r : {f.request(0x10, 0x01, 1, 7, {1, 'x'}),       // Identity name
                        f.request(0x10, 0x09, 0, 3, {1}),            // DOP class attribute
                        f.request(0x10, 0x09, 1, 4, {1}),            // DOP status
                        f.request(0x10, 0x32, 1, 15, {1}),           // Supervisor alarm enable
                        f.request(0x05, 0x08, 1, {}),                // DIP Reset
                        f.request(0x4C, 0x40, 1, {}, {0x03}),        // Release elsewhere
                        f.request(0x4B, 0x01, 1, {}, {0x03, 0})}) {  // Allocate elsewhere
    EXPECT_TRUE(classify(r, f.node()).empty()) << int{r.service} << " " << r.class_id;
  }
}

TEST(ExplicitPolicy, ARequestOfTwoClassesNeedsBoth) {
  Fixture f;
  // Set_Attributes_All of DOP 1 writes its Value and its managed fault action.
  const auto all = f.request(0x02, 0x09, 1, {}, {1, 0, 0, 0, 0, 0});
  ASSERT_EQ(classify(all, f.node()).size(), 2u);
  ExplicitPolicy outputs;
  outputs.allow_output_writes = true;
  const auto r = check(outputs, all, f.node());
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->kind, GuardedRequest::kManagedAttributeWrite);
  outputs.allow_managed_attribute_writes = true;
  EXPECT_FALSE(check(outputs, all, f.node()));
}

TEST(ExplicitPolicy, EveryClassHasItsOwnKey) {
  std::vector<std::string_view> keys;
  for (std::size_t i = 0; i < kGuardedRequestKinds; ++i) {
    const auto kind = static_cast<GuardedRequest>(i);
    keys.push_back(policy_key(kind));
    EXPECT_TRUE(allowing(kind).allows(kind));
    EXPECT_FALSE(allowing_all_but(kind).allows(kind));
    EXPECT_FALSE(ExplicitPolicy{}.allows(kind));
    EXPECT_NE(risk_of(kind), "?");
  }
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(std::unique(keys.begin(), keys.end()), keys.end());
}

}  // namespace
}  // namespace dnbridge::rack
