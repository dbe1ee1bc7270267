#pragma once
// A configuration read again, applied on the port's thread: the scan list
// and timings to the rack (rack::RackPort::reconfigure, only where they
// differ), then what the port keeps of each node (what was published of it,
// its poll count for the scan cycle), the instances of the nodes that go
// (removed, or now of another profile), the explicit policy, and one log
// line saying what changed.
#include <string>
#include <string_view>

#include "adapters/port/bus_metrics.hpp"
#include "adapters/port/node_publication.hpp"
#include "adapters/port/port_config.hpp"
#include "adapters/port/port_publisher.hpp"
#include "bridge/common/log.hpp"
#include "bridge/rack/explicit_gateway.hpp"
#include "bridge/rack/rack_port.hpp"

namespace dnbridge::port {

class PortReconfiguration {
 public:
  PortReconfiguration(rack::RackPort& port, NodePublication& publication, BusMetrics& metrics,
                      PortPublisher& publisher, Logger log)
      : port_(port),
        publication_(publication),
        metrics_(metrics),
        publisher_(publisher),
        log_(std::move(log)) {}

  // The port's first configuration: every node is new.
  void start(const PortLoopConfig& in_force);
  // Applies `next` over `in_force` (updated to it but for the port's name,
  // interface, master and periods, which need a restart). A configuration
  // the master refuses changes nothing (PortChange::refused).
  PortChange apply(PortLoopConfig& in_force, PortLoopConfig& next, rack::ExplicitGateway& gateway,
                   TimePoint now);

 private:
  // The instances of the nodes that go: removed, or configured again as a
  // node of another profile than `before` says.
  void dispose(const std::string& port, const rack::ScanListChange& sc,
               const std::array<std::string_view, devicenet::MacId::kMax + 1>& before);
  void log_change(const PortChange& change);

  rack::RackPort& port_;
  NodePublication& publication_;
  BusMetrics& metrics_;
  PortPublisher& publisher_;
  Logger log_;
};

}  // namespace dnbridge::port
