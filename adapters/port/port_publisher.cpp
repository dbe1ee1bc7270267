#include "adapters/port/port_publisher.hpp"

namespace dnbridge::port {

NodeStatusView NodeStatusView::of(const devicenet::Node& node) {
  NodeStatusView v;
  v.state = node.state();
  v.reason = node.reason();
  v.identity = node.identity();
  v.device_state = node.device_state();
  v.poll_period = node.config().poll_period;
  v.poll_epr = node.poll_epr();
  v.produced_size = node.config().profile.produced_size;
  v.consumed_size = node.config().profile.consumed_size;
  v.last_error = node.last_error();
  v.counters = node.counters();
  v.explicit_counters = node.explicit_counters();
  return v;
}

}  // namespace dnbridge::port
