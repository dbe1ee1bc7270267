#include "adapters/sim/cdn127/cdn127_slave.hpp"

#include <utility>

namespace dnbridge::sim {
namespace {

Group2Options wire_options(const SlaveOptions& o) noexcept {
  Group2Options w;
  w.vendor_id = profiles::cdn127::kVendorId;
  w.serial_number = o.serial_number;
  w.duplicate_mac_window = o.duplicate_mac_window;
  w.fragment_ack_timeout = o.fragment_ack_timeout;
  w.offline = o.offline;
  w.no_ack_of_last_request_fragment = o.no_ack_of_last_request_fragment;
  w.explicit_response_delay = o.explicit_response_delay;
  w.poll_response_delay = o.poll_response_delay;
  return w;
}

}  // namespace

Cdn127Slave::Cdn127Slave(can::FrameSink& sink, SlaveOptions options, Logger log)
    : Group2Slave(sink, wire_options(options), std::move(log)), device_(options) {}

}  // namespace dnbridge::sim
