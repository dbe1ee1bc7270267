// The bus scan against simulated CDN127s on the in-process bus, on a fake
// clock: what answers at MACs the scan list does not have is found with its
// identity and released; the scan list's nodes are never addressed and keep
// every poll; a node another master polls is not asked; nothing is asked
// twice.
#include <gtest/gtest.h>

#include <array>
#include <map>

#include "bridge/devicenet/wire/identifier.hpp"
#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

namespace cdn127 = profiles::cdn127;
using devicenet::BusScan;
using devicenet::group2_id;
using devicenet::Group2Message;
using devicenet::ScanOutcome;

class BusScanTest : public ::testing::Test {
 protected:
  void build(sim::SimRackConfig config) {
    rack_ = std::make_unique<sim::SimRack>(std::move(config));
    rack_->observe(events_);
    // Requests on the unconnected and the connected explicit port, per MAC.
    rack_->world().bus().set_tap([this](const sim::WireFrame& w) {
      for (unsigned m = 0; m <= devicenet::MacId::kMax; ++m) {
        if (w.frame.id == group2_id(mac(m), Group2Message::kUnconnectedExplicitRequest)) {
          ++unconnected_[m];
        }
        // Whole requests and first fragments, not fragment acknowledgements.
        if (w.frame.id == group2_id(mac(m), Group2Message::kMasterExplicitRequest) &&
            w.frame.len > 0 && (w.frame.data[0] & 0x80) == 0) {
          ++connected_[m];
        }
      }
    });
  }
  sim::SimRack& rack() { return *rack_; }
  TimePoint now() { return rack_->now(); }

  // Scans and runs until the scan's end is reported.
  const BusScan* scan() {
    const std::size_t before = events_.bus_scans.size();
    EXPECT_TRUE(rack_->scanner().scan_bus(now()).ok());
    EXPECT_EQ(rack_->scanner().scan_bus(now()).error(), Errc::kBusy);
    rack_->world().run_until([&] { return events_.bus_scans.size() > before; }, seconds(60));
    return events_.bus_scans.size() > before ? &events_.bus_scans.back() : nullptr;
  }

  std::unique_ptr<sim::SimRack> rack_;
  EventRecorder events_;
  std::array<unsigned, 64> unconnected_{};
  std::array<unsigned, 64> connected_{};
};

TEST_F(BusScanTest, FindsWhatAnswersLeavesTheScanListAloneAndAsksEachMacOnce) {
  build(rack_config({5, 6}));
  rack().add_device(sim::default_slave_options(mac(20)), now());
  rack().add_device(sim::default_slave_options(mac(41)), now());
  rack().start();
  ASSERT_TRUE(rack().world().run_until([&] { return rack().all_online(); }, seconds(30)));
  std::map<unsigned, std::uint64_t> polls;
  for (unsigned m : {5u, 6u}) polls[m] = rack().scanner().node(mac(m))->counters().responses;
  const auto unconnected_before = unconnected_;
  const auto connected_before = connected_;

  const auto started = now();
  const BusScan* result = scan();
  ASSERT_NE(result, nullptr);
  const Duration took = now() - started;
  EXPECT_TRUE(result->error.empty()) << result->error;

  // Every MAC but the master's (0) and the scan list's, once, in order.
  ASSERT_EQ(result->findings.size(), 61u);
  unsigned expected_mac = 1;
  for (const auto& f : result->findings) {
    while (expected_mac == 5 || expected_mac == 6) ++expected_mac;
    EXPECT_EQ(f.mac.value(), expected_mac);
    ++expected_mac;
    if (f.mac.value() == 20 || f.mac.value() == 41) {
      EXPECT_EQ(f.outcome, ScanOutcome::kIdentified) << f.detail;
      EXPECT_EQ(f.identity.vendor_id, cdn127::kVendorId);
      EXPECT_EQ(f.identity.product_type, cdn127::kProductType);
      EXPECT_EQ(f.identity.product_code, cdn127::kProductCode);
      // The simulated CDN127 answers its serial number as a UINT (as its
      // manual types it): the low 16 bits of 0x10000 + MAC.
      EXPECT_EQ(f.identity.serial_number, f.mac.value());
      EXPECT_EQ(f.identity.product_name, "CDN127");  // fragmented on the wire
      EXPECT_TRUE(f.detail.empty()) << f.detail;
      EXPECT_EQ(rack().device(f.mac).device().owner(), devicenet::MacId::kNone) << "left allocated";
      // Allocate and Release; six Gets.
      EXPECT_EQ(unconnected_[f.mac.value()] - unconnected_before[f.mac.value()], 2u);
      EXPECT_EQ(connected_[f.mac.value()] - connected_before[f.mac.value()], 6u);
    } else {
      EXPECT_EQ(f.outcome, ScanOutcome::kNoAnswer) << unsigned{f.mac.value()} << ": " << f.detail;
      EXPECT_EQ(unconnected_[f.mac.value()] - unconnected_before[f.mac.value()], 1u)
          << "MAC " << unsigned{f.mac.value()} << " asked more than once";
    }
  }
  // The scan list's nodes: never allocated by the scan (their explicit
  // connection carries only the master's keep-alive), every poll answered.
  for (unsigned m : {5u, 6u}) {
    EXPECT_EQ(unconnected_[m], unconnected_before[m]) << m;
    const auto& c = rack().scanner().node(mac(m))->counters();
    EXPECT_GT(c.responses, polls[m]);
    EXPECT_EQ(c.timeouts, 0u) << m;
    EXPECT_EQ(c.reconnects, 0u) << m;
    EXPECT_TRUE(rack().all_online());
  }
  // Eight MACs at a time, one second for a silent one: 59 silent MACs.
  EXPECT_LE(took, seconds(9));
  std::printf("[ measured ] bus scan of 61 MACs (2 answering) on the fake clock: %.1f s\n",
              std::chrono::duration<double>(took).count());
}

// Another master holds a node: the Allocate is refused (0x0C/0x01) and the
// node left alone; once this master has heard it answering the other's
// polls, it is not even asked.
TEST_F(BusScanTest, ANodeAnotherMasterHoldsIsLeftAloneAndNotAskedOnceHeard) {
  build(rack_config({5}));
  rack::PumpRack other_rack({pump(12)});
  devicenet::ScannerConfig other_port;
  other_port.master_mac = mac(9);
  sim::SimMaster other(rack().world(), rack::PumpRack::scanner_config(other_port, {pump(12)}),
                       other_rack);
  other_rack.attach(other.scanner());
  rack().add_device(sim::default_slave_options(mac(12)), now());
  other.scanner().start(now());
  ASSERT_TRUE(
      rack().world().run_until([&] { return other_rack.pump(mac(12))->online; }, seconds(10)));
  rack().start();
  ASSERT_TRUE(rack().world().run_until([&] { return rack().all_online(); }, seconds(30)));
  const auto outcome_of_12 = [](const BusScan& scan) {
    for (const auto& f : scan.findings) {
      if (f.mac.value() == 12) return f.outcome;
    }
    return ScanOutcome::kNotAsked;
  };
  const auto other_polls = [&] { return other.scanner().node(mac(12))->counters().responses; };

  // Not heard yet (this master has just started): asked, refused.
  ASSERT_FALSE(rack().scanner().unconfigured_heard(now()).test(12));
  auto before = unconnected_[12];
  auto polls = other_polls();
  const BusScan* first = scan();
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(outcome_of_12(*first), ScanOutcome::kOwnedByOtherMaster);
  EXPECT_EQ(unconnected_[12] - before, 1u) << "one Allocate, refused; nothing else";
  EXPECT_GT(other_polls(), polls + 50) << "the other master's polls were disturbed";
  EXPECT_TRUE(other_rack.pump(mac(12))->online);
  EXPECT_EQ(rack().device(mac(12)).device().owner(), 9u);

  // Heard answering the other master since: not asked.
  ASSERT_TRUE(rack().scanner().unconfigured_heard(now()).test(12));
  before = unconnected_[12];
  const BusScan* second = scan();
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(outcome_of_12(*second), ScanOutcome::kAnsweringOtherMaster);
  EXPECT_EQ(unconnected_[12], before) << "the scan asked a node another master polls";
  EXPECT_TRUE(other_rack.pump(mac(12))->online);
}

TEST_F(BusScanTest, AScanEndsWithThePortAndSaysWhatItDidNotAsk) {
  build(rack_config({5}));
  rack().start();
  ASSERT_TRUE(rack().world().run_until([&] { return rack().all_online(); }, seconds(30)));
  ASSERT_TRUE(rack().scanner().scan_bus(now()).ok());
  rack().world().run_for(milliseconds(1500));
  rack().scanner().stop(now());
  ASSERT_EQ(events_.bus_scans.size(), 1u);
  const BusScan& result = events_.bus_scans.back();
  EXPECT_NE(result.error.find("stopping"), std::string::npos) << result.error;
  ASSERT_EQ(result.findings.size(), 62u);
  std::size_t no_answer = 0;
  std::size_t not_asked = 0;
  for (const auto& f : result.findings) {
    no_answer += f.outcome == ScanOutcome::kNoAnswer;
    not_asked += f.outcome == ScanOutcome::kNotAsked;
  }
  EXPECT_EQ(no_answer, 8u);  // the first eight, silent for 1 s
  EXPECT_EQ(not_asked, 54u);
  EXPECT_EQ(rack().scanner().scan_bus(now()).error(), Errc::kStopped);
}

}  // namespace
}  // namespace dnbridge::test
