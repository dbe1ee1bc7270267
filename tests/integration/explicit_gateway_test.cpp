// The scanner transaction model over the master: every status code that can
// be provoked against simulated CDN127s, and repeats answered, not re-run.
#include "bridge/rack/explicit_gateway.hpp"

#include <gtest/gtest.h>

#include "bridge/devicenet/identifier.hpp"
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
    return static_cast<std::size_t>(
        std::count_if(replies.begin(), replies.end(), [&](const auto& r) { return r.txid == txid; }));
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
    gateway_ = std::make_unique<ExplicitGateway>(rack_->scanner(), limits_);
    harness_.gateway = gateway_.get();
  }
  void start() {
    rack_->start();
    rack_->world().run_until([&] { return rack_->pumps().pump(mac(1))->online &&
                                          rack_->pumps().pump(mac(2))->online &&
                                          rack_->pumps().pump(mac(3))->state == NodeState::kWrongDevice; },
                             seconds(30));
  }
  void run(Duration d = seconds(3)) { rack_->world().run_for(d); }
  TimePoint now() { return rack_->now(); }

  ExplicitGateway::Limits limits_{};
  std::unique_ptr<sim::SimRack> rack_;
  std::unique_ptr<ExplicitGateway> gateway_;
  GatewayHarness harness_;
};

TEST_F(Gateway, ExecuteReturnsTheDevicesDataAndCipStatus) {
  start();
  harness_.request(get_call(1, 1, cdn127::class_id::kIdentity, cdn127::identity_attr::kProductName), now());
  harness_.request(get_call(2, 1, cdn127::class_id::kIdentity, 99), now());
  EXPECT_EQ(gateway_->in_progress(), 2u);
  run();
  const auto* name = harness_.reply(1);
  ASSERT_NE(name, nullptr);
  EXPECT_EQ(name->status, TransactionStatus::kSuccess);
  EXPECT_EQ(name->general_status, 0);
  EXPECT_EQ(name->data, (std::vector<std::uint8_t>{6, 'C', 'D', 'N', '1', '2', '7'}));
  EXPECT_TRUE(name->retained);  // kept to answer repeats
  const auto* bad = harness_.reply(2);
  ASSERT_NE(bad, nullptr);
  // The device answered: the transaction completed, with its error status.
  EXPECT_EQ(bad->status, TransactionStatus::kSuccess);
  EXPECT_EQ(bad->general_status, 0x14);
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
  EXPECT_FALSE(harness_.reply(2)->retained);
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
  for (std::uint32_t t = 1; t <= 10; ++t) harness_.request(get_call(t, 2, 1, 1), now()), run(milliseconds(50));
  run();
  EXPECT_EQ(gateway_->retained(), 4u);
  const auto forgotten = gateway_->take_forgotten();
  ASSERT_EQ(forgotten.size(), 6u);
  EXPECT_EQ(forgotten.front(), (std::pair<std::string, std::uint32_t>{"tester", 1}));
  EXPECT_TRUE(gateway_->take_forgotten().empty());
  auto status = get_call(1, 2, 1, 1);
  status.command = 2;
  harness_.request(status, now());
  EXPECT_EQ(harness_.replies.back().status, TransactionStatus::kTxidUnknown);
}

}  // namespace
}  // namespace dnbridge::test
