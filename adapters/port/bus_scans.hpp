#pragma once
// A port's bus scan requests (BusScanRequest) and their answers. One scan at
// a time: a request while one runs waits for it (at most kMaxWaiters, the
// rest answered at once with "out of buffers"); one within kHoldoff after a
// complete scan gets that scan again, so that requests cannot make the bus
// scanned more often. The scan itself is the master's
// (devicenet::Scanner::scan_bus): this says when to start one, and answers
// its waiters when it ends.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "adapters/port/can_backend.hpp"
#include "adapters/port/port_publisher.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/scanner_events.hpp"

namespace dnbridge::port {

class BusScans {
 public:
  static constexpr std::size_t kMaxWaiters = 64;
  static constexpr Duration kHoldoff = seconds(30);

  BusScans(std::string port, PortPublisher& publisher)
      : port_(std::move(port)), publisher_(publisher) {}

  // A request, on the port's thread: answered at once (the last scan again,
  // or refused), or waiting for a scan. `scanning`: the master's scan runs;
  // `bus`: the bus as the loop last saw it. True: the request waits and
  // the caller starts the scan now; then start_refused if the master does
  // not start it.
  bool request(const ScanCall& call, bool scanning, BusState bus, TimePoint now);
  // The master would not start the scan: the request that asked for it is
  // refused with `why` (the master's state).
  void start_refused(const std::string& why);
  // The scan ended (ScannerObserver::on_bus_scan): every waiter is answered.
  void on_bus_scan(const devicenet::BusScan& scan, TimePoint at);

  std::size_t waiting() const { return waiters_.size(); }

 private:
  void answer(const ScanCall& call, const devicenet::BusScan& scan, TimePoint now);
  void refuse(const ScanCall& call, rack::TransactionStatus status, std::string message);

  std::string port_;
  PortPublisher& publisher_;
  std::vector<ScanCall> waiters_;
  std::optional<devicenet::BusScan> last_;
};

}  // namespace dnbridge::port
