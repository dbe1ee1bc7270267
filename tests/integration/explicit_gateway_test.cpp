// The scanner transaction model over the master: every status code that can
// be provoked against simulated CDN127s, repeats answered, not re-run, and
// the explicit policy: what it refuses, what it lets through.
#include "bridge/rack/explicit_gateway.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <functional>

#include "bridge/devicenet/wire/identifier.hpp"
#include "bridge/profiles/cdn127/objects.hpp"
#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

namespace cdn127 = profiles::cdn127;
using rack::ExplicitAnswer;
using rack::ExplicitCall;
using rack::ExplicitGateway;
using rack::TransactionStatus;

// Routes the master's explicit results to the gateway, as the port loop does.
class GatewayHarness final : public devicenet::ScannerObserver {
 public:
  void on_explicit_result(std::uint32_t id, MacId, const devicenet::ExplicitResult& r,
                          TimePoint at) override {
    if (gateway) {
      if (auto a = gateway->on_result(id, r, at)) replies.push_back(*a);
    }
  }
  void request(const ExplicitCall& call, TimePoint now) {
    if (auto a = gateway->on_request(call, now)) replies.push_back(*a);
  }
  const ExplicitAnswer* reply(std::uint32_t txid, std::size_t nth = 0) const {
    for (const auto& r : replies) {
      if (r.txid == txid && nth-- == 0) return &r;
    }
    return nullptr;
  }
  std::size_t count(std::uint32_t txid) const {
    return static_cast<std::size_t>(std::count_if(replies.begin(), replies.end(),
                                                  [&](const auto& r) { return r.txid == txid; }));
  }

  ExplicitGateway* gateway = nullptr;
  std::vector<ExplicitAnswer> replies;
};

ExplicitCall get_call(std::uint32_t txid, unsigned node, std::uint16_t cls, std::uint8_t attr) {
  ExplicitCall c;
  c.requester = "tester";
  c.txid = txid;
  c.command = 1;
  c.port = "A";
  c.mac = static_cast<std::uint8_t>(node);
  c.service = 0x0E;
  c.class_id = cls;
  c.instance_id = 1;
  c.attribute = attr;
  return c;
}

class Gateway : public ::testing::Test {
 protected:
  void SetUp() override {
    auto config = rack_config({1, 2, 3});
    config.pumps[2].identity = devicenet::ExpectedIdentity{59, 27, 9999};  // node 3: wrong device
    rack_ = std::make_unique<sim::SimRack>(config);
    rack_->observe(harness_);
    rack_->observe(events_);
    gateway_ = std::make_unique<ExplicitGateway>(rack_->scanner(), limits_, policy_,
                                                 Logger(log_, "port A"));
    harness_.gateway = gateway_.get();
  }
  void start() {
    rack_->start();
    rack_->world().run_until(
        [&] {
          return rack_->pumps().pump(mac(1))->online && rack_->pumps().pump(mac(2))->online &&
                 rack_->pumps().pump(mac(3))->state == NodeState::kWrongDevice;
        },
        seconds(30));
  }
  void run(Duration d = seconds(3)) { rack_->world().run_for(d); }
  TimePoint now() { return rack_->now(); }

  ExplicitGateway::Limits limits_{};
  rack::ExplicitPolicy policy_{};
  CountingLogSink log_;
  EventRecorder events_;
  std::unique_ptr<sim::SimRack> rack_;
  std::unique_ptr<ExplicitGateway> gateway_;
  GatewayHarness harness_;
};

TEST_F(Gateway, ExecuteReturnsTheDevicesDataAndCipStatus) {
  start();
  harness_.request(get_call(1, 1, cdn127::class_id::kIdentity, cdn127::identity_attr::kProductName),
                   now());
  harness_.request(get_call(2, 1, cdn127::class_id::kIdentity, 99), now());
  EXPECT_EQ(gateway_->in_progress(), 2u);
  run();
  const auto* name = harness_.reply(1);
  ASSERT_NE(name, nullptr);
  EXPECT_EQ(name->status, TransactionStatus::kSuccess);
  EXPECT_EQ(name->general_status, 0);
  EXPECT_EQ(name->data, (std::vector<std::uint8_t>{6, 'C', 'D', 'N', '1', '2', '7'}));
  const auto* bad = harness_.reply(2);
  ASSERT_NE(bad, nullptr);
  // The device answered: the transaction completed, with its error status.
  EXPECT_EQ(bad->status, TransactionStatus::kSuccess);
  EXPECT_EQ(bad->general_status, 0x14);
  EXPECT_EQ(gateway_->retained(), 2u);  // both kept to answer repeats
  EXPECT_NE(bad->message.find("attribute not supported"), std::string::npos) << bad->message;
}

TEST_F(Gateway, RepeatedRequestIsAnsweredAgainNotExecutedAgain) {
  start();
  // Count the serial-number requests that reach the bus.
  std::size_t on_wire = 0;
  rack_->world().bus().set_tap([&](const sim::WireFrame& w) {
    const auto& f = w.frame;
    if (f.id == devicenet::group2_id(mac(1), devicenet::Group2Message::kMasterExplicitRequest) &&
        f.len == 5 && f.data[1] == 0x0E && f.data[4] == cdn127::identity_attr::kSerialNumber) {
      ++on_wire;
    }
  });
  auto call = get_call(7, 1, cdn127::class_id::kIdentity, cdn127::identity_attr::kSerialNumber);
  harness_.request(call, now());
  harness_.request(call, now());  // retransmitted while in progress: no second execution
  run();
  harness_.request(call, now());  // and after completion: the same reply
  run();
  ASSERT_EQ(harness_.count(7), 2u);
  EXPECT_EQ(harness_.reply(7, 0)->data, harness_.reply(7, 1)->data);
  EXPECT_EQ(harness_.reply(7, 1)->status, TransactionStatus::kSuccess);
  EXPECT_EQ(on_wire, 1u);
}

TEST_F(Gateway, GetStatusTellsInProgressThenTheResult) {
  start();
  auto call = get_call(9, 2, cdn127::class_id::kIdentity, cdn127::identity_attr::kVendor);
  harness_.request(call, now());
  call.command = 2;
  harness_.request(call, now());
  ASSERT_NE(harness_.reply(9), nullptr);
  EXPECT_EQ(harness_.reply(9)->status, TransactionStatus::kInProgress);
  run();
  harness_.request(call, now());
  ASSERT_EQ(harness_.count(9), 3u);  // in progress, the completion, the status asked again
  EXPECT_EQ(harness_.reply(9, 2)->status, TransactionStatus::kSuccess);
  EXPECT_EQ(harness_.reply(9, 2)->data, (std::vector<std::uint8_t>{59, 0}));
}

TEST_F(Gateway, EveryRefusalHasItsStatus) {
  // Port not running yet.
  harness_.request(get_call(1, 1, 1, 1), now());
  EXPECT_EQ(harness_.reply(1)->status, TransactionStatus::kPortOffline);

  start();
  harness_.request(get_call(2, 40, 1, 1), now());
  EXPECT_EQ(harness_.reply(2)->status, TransactionStatus::kNotInScanList);
  EXPECT_EQ(gateway_->retained(), 0u);
  harness_.request(get_call(3, 200, 1, 1), now());
  EXPECT_EQ(harness_.reply(3)->status, TransactionStatus::kNotInScanList);

  auto unknown = get_call(4, 1, 1, 1);
  unknown.command = 2;
  harness_.request(unknown, now());
  EXPECT_EQ(harness_.reply(4)->status, TransactionStatus::kTxidUnknown);

  auto invalid = get_call(5, 1, 1, 1);
  invalid.command = 7;
  harness_.request(invalid, now());
  EXPECT_EQ(harness_.reply(5)->status, TransactionStatus::kInvalidCommand);

  harness_.request(get_call(6, 3, 1, 1), now());
  EXPECT_EQ(harness_.reply(6)->status, TransactionStatus::kCouldNotConnect);
  EXPECT_NE(harness_.reply(6)->message.find("wrong device"), std::string::npos);

  auto big = get_call(8, 1, 1, 1);
  big.service = 0x10;
  big.data.assign(600, 0);
  harness_.request(big, now());
  EXPECT_EQ(harness_.reply(8)->status, TransactionStatus::kInvalidSize);

  harness_.request(get_call(10, 1, 1, 1), now());
  auto other = get_call(10, 1, 1, 2);  // same txid, another request
  harness_.request(other, now());
  EXPECT_EQ(harness_.reply(10)->status, TransactionStatus::kOtherTransaction);
  run();

  rack_->device(mac(2)).disconnect();
  run(seconds(3));
  harness_.request(get_call(11, 2, 1, 1), now());
  EXPECT_EQ(harness_.reply(11)->status, TransactionStatus::kSlaveOffline);
}

TEST_F(Gateway, BusyConnectionAndFullTableAreRefused) {
  limits_.in_progress = 8;
  SetUp();
  start();
  // The node's explicit queue takes a few; then its connection is busy.
  std::uint32_t txid = 100;
  while (harness_.replies.empty() && txid < 120) {
    harness_.request(get_call(txid++, 1, cdn127::class_id::kIdentity, 1), now());
  }
  ASSERT_EQ(harness_.replies.size(), 1u);
  const std::uint32_t busy = txid - 1;
  EXPECT_EQ(harness_.reply(busy)->status, TransactionStatus::kConnectionBusy);
  EXPECT_GE(busy - 100, 5u);  // several were taken first
  // The rest of the table fills with requests to node 2.
  std::uint32_t more = 200;
  while (harness_.replies.size() == 1 && more < 220) {
    harness_.request(get_call(more++, 2, 1, 1), now());
  }
  ASSERT_EQ(harness_.replies.size(), 2u);
  EXPECT_EQ(harness_.reply(more - 1)->status, TransactionStatus::kOutOfBuffers);
  EXPECT_EQ(gateway_->in_progress(), 8u);
  run();
  for (std::uint32_t t = 100; t < busy; ++t) {
    ASSERT_NE(harness_.reply(t), nullptr) << t;
    EXPECT_EQ(harness_.reply(t)->status, TransactionStatus::kSuccess) << t;
  }
  EXPECT_EQ(gateway_->in_progress(), 0u);
}

TEST_F(Gateway, OneRequesterCannotTakeEverySlot) {
  limits_.per_requester = 3;
  SetUp();
  start();
  // "greedy" fills its share over two nodes; the next is refused at once.
  for (std::uint32_t txid = 1; txid <= 4; ++txid) {
    harness_.request(get_call(txid, 1 + txid % 2, cdn127::class_id::kIdentity, 1), now());
  }
  ASSERT_EQ(harness_.replies.size(), 1u);
  const auto* refused = harness_.reply(4);
  ASSERT_NE(refused, nullptr);
  EXPECT_EQ(refused->status, TransactionStatus::kOutOfBuffers);
  EXPECT_NE(refused->message.find("3 transactions of \"tester\""), std::string::npos)
      << refused->message;
  EXPECT_EQ(gateway_->refused_for_limits(), 1u);
  // Another requester is served meanwhile.
  auto other = get_call(1, 2, cdn127::class_id::kIdentity, 1);
  other.requester = "patient";
  harness_.request(other, now());
  EXPECT_EQ(gateway_->in_progress(), 4u);
  run();
  EXPECT_EQ(gateway_->in_progress(), 0u);
  // Its share is back once its transactions completed.
  harness_.request(get_call(5, 1, cdn127::class_id::kIdentity, 1), now());
  EXPECT_EQ(gateway_->in_progress(), 1u);
  EXPECT_EQ(gateway_->refused_for_limits(), 1u);
}

TEST_F(Gateway, CompletedTransactionsAreForgottenAfterTheRetention) {
  limits_.retention = seconds(20);
  SetUp();
  start();
  auto call = get_call(1, 1, cdn127::class_id::kIdentity, 1);
  harness_.request(call, now());
  run();
  ASSERT_EQ(gateway_->retained(), 1u);
  const TimePoint done = gateway_->next_expiry() - seconds(20);
  EXPECT_LE(done, now());
  gateway_->expire(done + seconds(19));
  EXPECT_EQ(gateway_->retained(), 1u);
  gateway_->expire(done + seconds(20));
  EXPECT_EQ(gateway_->retained(), 0u);
  EXPECT_EQ(gateway_->next_expiry(), kNever);
  // A repeat now is a new execution.
  harness_.request(call, now());
  EXPECT_EQ(gateway_->in_progress(), 1u);
}

TEST_F(Gateway, ResetAllForgetsTheRequestersTransactions) {
  start();
  auto call = get_call(1, 1, cdn127::class_id::kIdentity, 1);
  harness_.request(call, now());
  run();
  EXPECT_EQ(gateway_->retained(), 1u);
  auto reset = get_call(2, 1, 0, 0);
  reset.command = 3;
  harness_.request(reset, now());
  EXPECT_EQ(harness_.reply(2)->status, TransactionStatus::kSuccess);
  EXPECT_EQ(gateway_->retained(), 0u);
  // txid 1 can be used afresh.
  call.attribute = 2;
  harness_.request(call, now());
  run();
  EXPECT_EQ(harness_.count(1), 2u);
  EXPECT_EQ(harness_.reply(1, 1)->data, (std::vector<std::uint8_t>{27, 0}));
}

TEST_F(Gateway, CompletedTransactionsAreRetainedWithinTheLimit) {
  limits_.retained = 4;
  SetUp();
  start();
  for (std::uint32_t t = 1; t <= 10; ++t)
    harness_.request(get_call(t, 2, 1, 1), now()), run(milliseconds(50));
  run();
  EXPECT_EQ(gateway_->retained(), 4u);
  // The oldest six are forgotten, the newest four kept.
  auto status = get_call(1, 2, 1, 1);
  status.command = 2;
  harness_.request(status, now());
  EXPECT_EQ(harness_.replies.back().status, TransactionStatus::kTxidUnknown);
  status.txid = 6;
  harness_.request(status, now());
  EXPECT_EQ(harness_.replies.back().status, TransactionStatus::kTxidUnknown);
  status.txid = 7;
  harness_.request(status, now());
  EXPECT_EQ(harness_.replies.back().status, TransactionStatus::kSuccess);
}

// One request of each class the explicit policy guards, to node `node`.
struct GuardedCall {
  rack::GuardedRequest kind;
  ExplicitCall call;
};

std::vector<GuardedCall> guarded_calls(std::uint32_t first_txid, unsigned node) {
  auto make = [&](std::uint32_t txid, std::uint8_t service, std::uint16_t cls,
                  std::uint16_t instance, std::optional<std::uint8_t> attribute,
                  std::vector<std::uint8_t> data) {
    ExplicitCall c = get_call(first_txid + txid, node, cls, 0);
    c.service = service;
    c.instance_id = instance;
    c.attribute = attribute;
    c.data = std::move(data);
    return c;
  };
  using rack::GuardedRequest;
  return {
      {GuardedRequest::kAllocateRelease, make(0, 0x4C, 0x03, 1, {}, {0x03})},        // Release all
      {GuardedRequest::kConnectionChange, make(1, 0x10, 0x05, 2, 9, {0x00, 0x00})},  // poll EPR 0
      {GuardedRequest::kOutputWrite,
       make(2, 0x10, cdn127::class_id::kDiscreteOutputPoint, 1, 3, {0x01})},  // pump on
      {GuardedRequest::kManagedAttributeWrite,
       make(3, 0x10, cdn127::class_id::kConfiguration, 1, 1, {0x81})},  // Mode
      {GuardedRequest::kIdentityReset, make(4, 0x05, cdn127::class_id::kIdentity, 1, {}, {})},
  };
}

// Counts the master's explicit requests to `node` on the bus, Gets (the
// keep-alive) aside.
std::function<void(const sim::WireFrame&)> count_changes_to(unsigned node, std::size_t& count) {
  return [node, &count](const sim::WireFrame& w) {
    const auto& f = w.frame;
    if (f.id == devicenet::group2_id(mac(node), devicenet::Group2Message::kMasterExplicitRequest) &&
        f.len >= 2 && f.data[1] != 0x0E) {
      ++count;
    }
  };
}

TEST_F(Gateway, EveryGuardedClassIsRefusedByDefault) {
  start();
  run();  // past the start-up's own writes
  std::size_t on_wire = 0;
  rack_->world().bus().set_tap(count_changes_to(1, on_wire));
  const auto calls = guarded_calls(100, 1);
  for (const auto& g : calls) {
    harness_.request(g.call, now());
    const auto* r = harness_.reply(g.call.txid);
    ASSERT_NE(r, nullptr) << rack::policy_key(g.kind);
    EXPECT_EQ(r->status, TransactionStatus::kInvalidCommand) << r->message;
    EXPECT_EQ(gateway_->retained(), 0u);  // not a transaction: a new txid is not needed to retry
    EXPECT_NE(r->message.find(std::string(rack::policy_key(g.kind)) + " = true"), std::string::npos)
        << r->message;
    EXPECT_EQ(gateway_->refused_by_policy(g.kind), 1u);
    // Logged with its requester.
    EXPECT_NE(log_.last_warning.find("\"tester\""), std::string::npos) << log_.last_warning;
    EXPECT_NE(log_.last_warning.find(fmt::format("txid {}", g.call.txid)), std::string::npos);
  }
  EXPECT_EQ(gateway_->refused_by_policy(), calls.size());
  EXPECT_EQ(log_.warnings, calls.size());
  EXPECT_EQ(gateway_->in_progress(), 0u);
  run();
  EXPECT_EQ(on_wire, 0u);
  EXPECT_TRUE(rack_->pumps().pump(mac(1))->online);
  EXPECT_EQ(events_.of(mac(1)).back().to, NodeState::kOnline);
  EXPECT_EQ(rack_->device(mac(1)).device().counters().restarts, 1u);  // its power-up only
}

TEST_F(Gateway, RefusalsAreLoggedAtALimitedRate) {
  start();
  const auto release = guarded_calls(1, 1).front().call;
  for (std::uint32_t i = 0; i < 50; ++i) {
    auto c = release;
    c.txid = 1000 + i;
    harness_.request(c, now());
    EXPECT_EQ(harness_.replies.back().status, TransactionStatus::kInvalidCommand);
  }
  EXPECT_EQ(gateway_->refused_by_policy(), 50u);
  EXPECT_EQ(log_.warnings, 5u);  // RateLimitedLog's burst per window
  run(seconds(11));
  harness_.request(release, now());
  EXPECT_EQ(log_.warnings, 6u);
  EXPECT_NE(log_.last_warning.find("45 more refusals not logged"), std::string::npos)
      << log_.last_warning;
}

TEST_F(Gateway, EachGuardedClassIsExecutedWhenThePolicyAllowsIt) {
  for (const auto& g : guarded_calls(100, 1)) {
    SCOPED_TRACE(rack::policy_key(g.kind));
    policy_ = rack::ExplicitPolicy{};
    policy_.allow(g.kind, true);
    harness_.replies.clear();
    SetUp();
    start();
    std::size_t on_wire = 0;
    rack_->world().bus().set_tap(count_changes_to(1, on_wire));
    harness_.request(g.call, now());
    EXPECT_EQ(harness_.reply(g.call.txid), nullptr);  // executing: its reply comes later
    EXPECT_EQ(gateway_->in_progress(), 1u);
    // Sent, and said so with its requester.
    EXPECT_NE(log_.last_info.find(fmt::format("\"tester\" (txid {})", g.call.txid)),
              std::string::npos)
        << log_.last_info;
    EXPECT_NE(log_.last_info.find(fmt::format("allowed by {}", rack::policy_key(g.kind))),
              std::string::npos)
        << log_.last_info;
    ASSERT_TRUE(rack_->world().run_until([&] { return harness_.reply(g.call.txid) != nullptr; },
                                         seconds(5)));
    // Until its reply (after it, a Release or a Reset has the node start up again).
    EXPECT_EQ(on_wire, 1u);
    EXPECT_EQ(gateway_->refused_by_policy(), 0u);
    EXPECT_NE(harness_.reply(g.call.txid)->status, TransactionStatus::kInvalidCommand)
        << harness_.reply(g.call.txid)->message;
  }
}

// During the start-up too: a Set landing after the bridge's read-back would
// leave the node online with a configuration (or safe state) it never saw.
TEST_F(Gateway, AManagedAttributeSetIsRefusedDuringTheStartUpToo) {
  rack_->start();
  // Node 1 connected and in its start-up, not online yet.
  ASSERT_TRUE(rack_->world().run_until(
      [&] { return rack_->scanner().node(mac(1))->state() == NodeState::kIdentifying; },
      seconds(10)));
  const auto mode = guarded_calls(1, 1)[3].call;
  ASSERT_EQ(mode.class_id, cdn127::class_id::kConfiguration);
  harness_.request(mode, now());
  ASSERT_NE(harness_.reply(mode.txid), nullptr);
  EXPECT_EQ(harness_.reply(mode.txid)->status, TransactionStatus::kInvalidCommand);
  EXPECT_EQ(gateway_->refused_by_policy(), 1u);
  EXPECT_EQ(gateway_->in_progress(), 0u);
  // The node comes online with the configuration it read back.
  ASSERT_TRUE(
      rack_->world().run_until([&] { return rack_->pumps().pump(mac(1))->online; }, seconds(10)));
}

TEST_F(Gateway, AnAllowedReleaseIsFollowedByTheBridgeReconnecting) {
  namespace alloc = devicenet::allocation;
  const std::uint8_t both = alloc::kExplicit | alloc::kPoll;
  for (const std::uint8_t choice : {both, alloc::kPoll, alloc::kExplicit}) {
    SCOPED_TRACE(fmt::format("Release choice 0x{:02X}", choice));
    policy_.allow_allocate_release = true;
    events_.transitions.clear();
    harness_.replies.clear();
    SetUp();
    start();
    const auto& device = rack_->device(mac(1)).device().device();
    ASSERT_EQ(device.allocation_choice(), both);
    const std::size_t before = events_.of(mac(1)).size();
    const std::size_t node2_before = events_.of(mac(2)).size();

    auto release = guarded_calls(1, 1).front().call;
    release.data = {choice};
    harness_.request(release, now());
    ASSERT_TRUE(rack_->world().run_until([&] { return harness_.reply(release.txid) != nullptr; },
                                         seconds(5)));
    EXPECT_EQ(harness_.reply(release.txid)->status, TransactionStatus::kSuccess)
        << harness_.reply(release.txid)->message;
    EXPECT_EQ(harness_.reply(release.txid)->general_status, 0);
    EXPECT_EQ(device.allocation_choice(), both & ~choice);  // the device dropped them

    // The master notices (no poll response, or no answer to its keep-alive,
    // for 4 x EPR) and allocates again.
    const TimePoint released = now();
    ASSERT_TRUE(rack_->world().run_until(
        [&] {
          return events_.of(mac(1)).size() > before + 1 && rack_->pumps().pump(mac(1))->online;
        },
        seconds(30)));
    const auto after = events_.of(mac(1));
    EXPECT_EQ(after[before].from, NodeState::kOnline);
    EXPECT_EQ(after[before].to, NodeState::kAbsent);
    EXPECT_NE(after[before].reason.find("4 x EPR"), std::string::npos) << after[before].reason;
    EXPECT_EQ(after.back().to, NodeState::kOnline);
    // 4 x the poll EPR (2 s) or the explicit one (10 s), then the first
    // allocation retry and the start-up.
    EXPECT_LT(after.back().at - released, seconds(12));
    EXPECT_EQ(device.allocation_choice(), both);
    // Node 2 never noticed.
    EXPECT_EQ(events_.of(mac(2)).size(), node2_before);
    EXPECT_TRUE(rack_->pumps().pump(mac(2))->online);
  }
}

}  // namespace
}  // namespace dnbridge::test
