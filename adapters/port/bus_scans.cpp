#include "adapters/port/bus_scans.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

namespace dnbridge::port {

bool BusScans::request(const ScanCall& call, bool scanning, BusState bus, TimePoint now) {
  // A request written again while its scan runs (a requester repeats until
  // answered) is the same transaction: it waits once.
  if (std::any_of(waiters_.begin(), waiters_.end(), [&](const ScanCall& w) {
        return w.requester == call.requester && w.txid == call.txid;
      })) {
    return false;
  }
  if (last_ && last_->error.empty() && now - last_->finished < kHoldoff && !scanning) {
    answer(call, *last_, now);
    return false;
  }
  if (waiters_.size() >= kMaxWaiters) {
    refuse(call, rack::TransactionStatus::kOutOfBuffers,
           fmt::format("{} requests already wait for port {}'s bus scan", kMaxWaiters, port_));
    return false;
  }
  if (!scanning && bus_lost(bus)) {
    // Every MAC would be silent: a scan would say nothing is there.
    refuse(call, rack::TransactionStatus::kPortOffline,
           fmt::format("port {}: the bus is {}: no bus scan", port_, to_string(bus)));
    return false;
  }
  // Waiting before the scan starts: a scan with nothing to ask ends at once.
  waiters_.push_back(call);
  return !scanning;
}

void BusScans::start_refused(const std::string& why) {
  const ScanCall call = waiters_.back();
  waiters_.pop_back();
  refuse(call, rack::TransactionStatus::kPortOffline,
         fmt::format("port {} is not scanning its nodes ({}): no bus scan", port_, why));
}

void BusScans::on_bus_scan(const devicenet::BusScan& scan, TimePoint at) {
  last_ = scan;
  std::vector<ScanCall> waiters;
  waiters.swap(waiters_);
  for (const auto& call : waiters) answer(call, scan, at);
}

void BusScans::refuse(const ScanCall& call, rack::TransactionStatus status, std::string message) {
  publisher_.bus_scan_reply(port_, port::refuse(call, status, std::move(message)));
}

void BusScans::answer(const ScanCall& call, const devicenet::BusScan& scan, TimePoint now) {
  BusScanAnswer a;
  a.requester = call.requester;
  a.txid = call.txid;
  a.duration = scan.finished - scan.started;
  a.age = now - scan.finished;
  a.findings = scan.findings;
  const auto seconds_of = [](Duration d) { return std::chrono::duration<double>(d).count(); };
  if (scan.error.empty()) {
    a.status = rack::TransactionStatus::kSuccess;
    a.message =
        a.age > Duration::zero()
            ? fmt::format("port {}: the bus scan of {:.1f} s ago (at most one every {:.0f} s)",
                          port_, seconds_of(a.age), seconds_of(kHoldoff))
            : fmt::format("port {}: bus scanned in {:.1f} s", port_, seconds_of(a.duration));
  } else {
    a.status = rack::TransactionStatus::kPortOffline;
    a.message = fmt::format("port {}: bus scan cut short ({})", port_, scan.error);
  }
  publisher_.bus_scan_reply(port_, a);
}

}  // namespace dnbridge::port
