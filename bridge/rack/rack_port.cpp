#include "bridge/rack/rack_port.hpp"

namespace dnbridge::rack {

RackPort::RackPort(devicenet::ScannerConfig port, const std::vector<PumpConfig>& pumps,
                   can::FrameSink& sink, Logger log,
                   const std::function<void(devicenet::ScannerConfig&)>& adjust)
    : pumps_(pumps) {
  observers_.add(pumps_);
  auto scan_list = PumpRack::scanner_config(std::move(port), pumps);
  if (adjust) adjust(scan_list);
  scanner_.emplace(std::move(scan_list), sink, observers_, std::move(log));
  pumps_.attach(*scanner_);
}

}  // namespace dnbridge::rack
