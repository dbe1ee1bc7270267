#include "adapters/metrics/rack_metrics.hpp"

#include <fmt/format.h>

#include <chrono>
#include <stdexcept>
#include <utility>

namespace dnbridge::metrics {
namespace {

using prometheus::ClientMetric;
using prometheus::MetricFamily;
using prometheus::MetricType;
using Labels = std::vector<ClientMetric::Label>;

constexpr devicenet::NodeState kNodeStates[] = {devicenet::NodeState::kAbsent,
                                                devicenet::NodeState::kIdentifying,
                                                devicenet::NodeState::kConfiguring,
                                                devicenet::NodeState::kVerifying,
                                                devicenet::NodeState::kOnline,
                                                devicenet::NodeState::kWrongDevice,
                                                devicenet::NodeState::kConfigurationFault,
                                                devicenet::NodeState::kOwnedByOtherMaster,
                                                devicenet::NodeState::kStopped,
                                                devicenet::NodeState::kDeviceFault};
constexpr devicenet::PortState kPortStates[] = {
    devicenet::PortState::kStopped, devicenet::PortState::kCheckingMac,
    devicenet::PortState::kRunning, devicenet::PortState::kStopping,
    devicenet::PortState::kDuplicateMac};
constexpr port::BusState kBusStates[] = {
    port::BusState::kErrorActive, port::BusState::kErrorWarning, port::BusState::kErrorPassive,
    port::BusState::kBusOff,      port::BusState::kUnknown,      port::BusState::kDown};

// The families of one scrape, by name, in the order first used.
class Families {
 public:
  void gauge(const char* name, const char* help, Labels labels, double value) {
    add(name, help, MetricType::Gauge, std::move(labels)).gauge.value = value;
  }
  void counter(const char* name, const char* help, Labels labels, double value) {
    add(name, help, MetricType::Counter, std::move(labels)).counter.value = value;
  }
  std::vector<MetricFamily> take() { return std::move(families_); }

 private:
  ClientMetric& add(const char* name, const char* help, MetricType type, Labels labels) {
    auto it = index_.find(name);
    if (it == index_.end()) {
      it = index_.emplace(name, families_.size()).first;
      families_.push_back(MetricFamily{name, help, type, {}});
    }
    auto& family = families_[it->second];
    family.metric.push_back(ClientMetric{});
    family.metric.back().label = std::move(labels);
    return family.metric.back();
  }
  std::vector<MetricFamily> families_;
  std::map<std::string, std::size_t> index_;
};

Labels with(Labels labels, std::string name, std::string value) {
  labels.push_back({std::move(name), std::move(value)});
  return labels;
}

// A port's figures from its last PortStatus.
void add_port_status(Families& f, const Labels& port, const port::PortStatusView& s) {
  for (auto state : kPortStates) {
    f.gauge("dnbridge_port_state", "The port's state: 1 for the one it is in",
            with(port, "state", std::string(devicenet::to_string(state))),
            s.state == state ? 1 : 0);
  }
  for (auto state : kBusStates) {
    f.gauge("dnbridge_can_bus_state", "The CAN controller's state: 1 for the one it is in",
            with(port, "state", std::string(port::to_string(state))), s.bus.state == state ? 1 : 0);
  }
  f.gauge("dnbridge_can_transmit_errors", "The controller's transmit error counter", port,
          s.bus.tx_errors);
  f.gauge("dnbridge_can_receive_errors", "The controller's receive error counter", port,
          s.bus.rx_errors);
  f.counter("dnbridge_can_frames_total", "Frames on the bus, both ways", port,
            static_cast<double>(s.bus.frames));
  f.gauge("dnbridge_can_bus_load_ratio", "Share of the bus's time its frames take (0..1)", port,
          s.bus_load_percent / 100.0);
  f.gauge("dnbridge_port_scan_cycle_seconds", "Mean interval between two polls of an online node",
          port, s.scan_cycle_ms / 1000.0);
  f.gauge("dnbridge_port_nodes_online", "Nodes online (polled)", port, s.nodes_online);
  f.gauge("dnbridge_port_nodes_configured", "Nodes of the port's configuration", port,
          s.nodes_configured);
  f.gauge("dnbridge_port_unconfigured_nodes",
          "Nodes heard on the bus at MACs the configuration does not have", port,
          static_cast<double>(s.unconfigured_macs.size()));
  f.gauge("dnbridge_port_explicit_outstanding",
          "Explicit requests queued for the port or executing", port, s.explicit_outstanding);
  f.counter("dnbridge_port_explicit_refused_for_limits_total",
            "Explicit requests refused for the bridge's limits (status 9)", port,
            static_cast<double>(s.explicit_refused_for_limits));
  f.gauge("dnbridge_port_loop_longest_pass_seconds",
          "The port loop's longest pass since its previous status (wall time)", port,
          s.loop_longest_pass_ms / 1000.0);
}

// The bridge process's DDS queues and readers.
void add_process(Families& f, const Labels& rack, const ProcessCounters& p) {
  for (const auto& q : p.queues) {
    const Labels labels = with(rack, "queue", q.name);
    f.counter("dnbridge_dds_samples_written_total", "DDS samples written from the queue", labels,
              static_cast<double>(q.written));
    f.counter("dnbridge_dds_samples_refused_total", "Samples not queued: the queue was full",
              labels, static_cast<double>(q.refused));
    f.gauge("dnbridge_dds_queue_depth", "Samples waiting to be written", labels,
            static_cast<double>(q.depth));
  }
  f.counter("dnbridge_dds_samples_taken_total", "DDS samples taken by the bridge",
            with(rack, "topic", "PumpCommand"), static_cast<double>(p.commands_taken));
  f.counter("dnbridge_dds_samples_taken_total", "DDS samples taken by the bridge",
            with(rack, "topic", "ExplicitRequest"), static_cast<double>(p.requests_taken));
  f.counter("dnbridge_dds_command_holdoffs_total",
            "Times PumpCommand samples came within 1 ms of the take before them (a flood) and "
            "waited in the reader for the next take, which takes each pump's newest",
            rack, static_cast<double>(p.command_holdoffs));
  f.counter("dnbridge_dds_state_write_failures_total",
            "PumpState, NodeStatus and PortStatus writes, disposals and unregistrations that "
            "failed (logged; the instance's next sample follows)",
            rack, static_cast<double>(p.state_write_failures));
}

}  // namespace

RackMetrics::RackMetrics(std::string rack, std::function<ProcessCounters()> process)
    : rack_(std::move(rack)), process_(std::move(process)) {}

RackMetrics::NodeEntry& RackMetrics::note_node(const std::string& port,
                                               const rack::NodeView& view) {
  auto& node = ports_[port].nodes[view.mac.value()];
  node.name = view.name;
  node.commands_accepted = view.commands_accepted;
  node.commands_refused = view.commands_refused;
  return node;
}

void RackMetrics::node_state(const std::string& port, const rack::NodeView& view, TimePoint) {
  std::lock_guard lock(mutex_);
  note_node(port, view);
}

void RackMetrics::node_status(const std::string& port, const rack::NodeView& view,
                              const port::NodeStatusView& status, TimePoint) {
  std::lock_guard lock(mutex_);
  auto& node = note_node(port, view);
  node.has_status = true;
  node.state = status.state;
  node.counters = status.counters;
  node.explicit_counters = status.explicit_counters;
}

void RackMetrics::port_status(const port::PortStatusView& status, TimePoint) {
  std::lock_guard lock(mutex_);
  auto& entry = ports_[status.port];
  entry.status = status;
  entry.stopped = false;
}

void RackMetrics::port_stopped(const std::string& port) {
  std::lock_guard lock(mutex_);
  ports_[port].stopped = true;
}

void RackMetrics::node_removed(const std::string& port, devicenet::MacId mac) {
  std::lock_guard lock(mutex_);
  ports_[port].nodes.erase(mac.value());
}

std::vector<MetricFamily> RackMetrics::Collect() const {
  Families f;
  {
    // A copy, so that the ports' threads wait only for it, not for the
    // families and their labels.
    std::map<std::string, PortEntry> ports;
    {
      std::lock_guard lock(mutex_);
      ports = ports_;
    }
    for (const auto& [name, entry] : ports) {
      const Labels port{{"rack", rack_}, {"port", name}};
      const auto* s = entry.status ? &*entry.status : nullptr;
      f.gauge("dnbridge_port_up", "1 while the port's loop runs and scans its bus, else 0", port,
              !entry.stopped && s && s->state == devicenet::PortState::kRunning ? 1 : 0);
      if (s) add_port_status(f, port, *s);
      for (const auto& [mac, node] : entry.nodes) {
        const Labels labels = with(with(port, "mac", std::to_string(mac)), "name", node.name);
        f.counter("dnbridge_node_commands_accepted_total", "Pump commands applied", labels,
                  static_cast<double>(node.commands_accepted));
        f.counter("dnbridge_node_commands_refused_total",
                  "Pump commands refused (node not online, bad value)", labels,
                  static_cast<double>(node.commands_refused));
        if (!node.has_status) continue;
        f.gauge("dnbridge_node_online", "1 while the node is online (polled), else 0", labels,
                !entry.stopped && node.state == devicenet::NodeState::kOnline ? 1 : 0);
        for (auto state : kNodeStates) {
          f.gauge("dnbridge_node_state", "The node's life-cycle state: 1 for the one it is in",
                  with(labels, "state", std::string(devicenet::to_string(state))),
                  node.state == state ? 1 : 0);
        }
        const auto& c = node.counters;
        f.counter("dnbridge_node_polls_total", "Polls sent", labels, static_cast<double>(c.polls));
        f.counter("dnbridge_node_poll_timeouts_total", "Polls not answered in time", labels,
                  static_cast<double>(c.timeouts));
        f.counter("dnbridge_node_poll_errors_total", "Bad poll responses (length, order, late)",
                  labels, static_cast<double>(c.errors));
        f.counter("dnbridge_node_reconnects_total", "Returns from online to allocation", labels,
                  static_cast<double>(c.reconnects));
        f.counter("dnbridge_node_cos_messages_total",
                  "Messages of the input connection taken: change of state or cyclic (the "
                  "device's retries included), or bit-strobe responses",
                  labels, static_cast<double>(c.cos_messages));
        f.counter("dnbridge_node_cos_retries_total",
                  "Change-of-state or cyclic messages the device sent again (an acknowledgment "
                  "it missed)",
                  labels, static_cast<double>(c.cos_retries));
        f.counter("dnbridge_node_heartbeats_missed_total",
                  "Input connections (change of state, cyclic, bit-strobe) lost: 4 x EPR "
                  "without a message",
                  labels, static_cast<double>(c.heartbeats_missed));
        f.counter("dnbridge_node_explicit_requests_total",
                  "Explicit requests sent to the node (the bridge's own and remote ones)", labels,
                  static_cast<double>(node.explicit_counters.requests));
        f.counter("dnbridge_node_explicit_timeouts_total", "Explicit requests not answered in time",
                  labels, static_cast<double>(node.explicit_counters.timeouts));
      }
    }
  }
  if (process_) add_process(f, Labels{{"rack", rack_}}, process_());
  return f.take();
}

MetricsServer::MetricsServer(const std::string& listen, std::shared_ptr<RackMetrics> metrics)
    : metrics_(std::move(metrics)) {
  try {
    // civetweb's listening_ports takes "HOST:PORT" as given.
    exposer_ = std::make_unique<prometheus::Exposer>(listen, 2);
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("[metrics] listen = \"{}\": {}", listen, e.what()));
  }
  exposer_->RegisterCollectable(metrics_);
}

}  // namespace dnbridge::metrics
