#pragma once
// The bridge's metrics for Prometheus. RackMetrics keeps the last view of
// every port and node its port loops publish (a PortPublisher beside the DDS
// one, called on the ports' threads) and, at each scrape, on the HTTP
// server's thread, turns them and the process's own counters into metric
// families:
//
//   per port   dnbridge_port_up, dnbridge_port_state{state}, dnbridge_can_bus_state{state},
//              dnbridge_can_transmit_errors, dnbridge_can_receive_errors,
//              dnbridge_can_frames_total, dnbridge_can_bus_load_ratio,
//              dnbridge_port_scan_cycle_seconds, dnbridge_port_nodes_online,
//              dnbridge_port_nodes_configured, dnbridge_port_unconfigured_nodes,
//              dnbridge_port_explicit_outstanding,
//              dnbridge_port_explicit_refused_for_limits_total,
//              dnbridge_port_loop_longest_pass_seconds
//   per node   dnbridge_node_online, dnbridge_node_state{state}, dnbridge_node_polls_total,
//              dnbridge_node_poll_timeouts_total, dnbridge_node_poll_errors_total,
//              dnbridge_node_cos_messages_total, dnbridge_node_cos_retries_total,
//              dnbridge_node_heartbeats_missed_total,
//              dnbridge_node_reconnects_total, dnbridge_node_commands_accepted_total,
//              dnbridge_node_commands_refused_total, dnbridge_node_explicit_requests_total,
//              dnbridge_node_explicit_timeouts_total
//   process    dnbridge_dds_samples_written_total{queue},
//              dnbridge_dds_samples_refused_total{queue}, dnbridge_dds_queue_depth{queue},
//              dnbridge_dds_samples_taken_total{topic}, dnbridge_dds_command_holdoffs_total,
//              dnbridge_dds_state_write_failures_total
//
// Labels: rack and port on every port and node series, mac and name on a
// node's. Units in the names (seconds, ratio), counters end in _total.
#include <prometheus/client_metric.h>
#include <prometheus/collectable.h>
#include <prometheus/exposer.h>
#include <prometheus/metric_family.h>
#include <prometheus/metric_type.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "adapters/port/port_publisher.hpp"

namespace dnbridge::metrics {

// The process's DDS side, read at each scrape.
struct ProcessCounters {
  struct Queue {
    std::string name;  // "replies"
    std::uint64_t written = 0;
    std::uint64_t refused = 0;  // not queued: the queue was full
    std::uint64_t depth = 0;    // waiting now
  };
  std::vector<Queue> queues;
  std::uint64_t commands_taken = 0;        // PumpCommand samples
  std::uint64_t requests_taken = 0;        // ExplicitRequest samples
  std::uint64_t command_holdoffs = 0;      // DdsInput::command_holdoffs
  std::uint64_t state_write_failures = 0;  // DdsPublisher::state_write_failures
};

class RackMetrics final : public port::PortPublisher, public prometheus::Collectable {
 public:
  RackMetrics(std::string rack, std::function<ProcessCounters()> process);

  // port::PortPublisher: keeps the last views (the ports' threads).
  void node_state(const std::string& port, const rack::NodeView& node, TimePoint) override;
  void node_status(const std::string& port, const rack::NodeView& node,
                   const port::NodeStatusView& status, TimePoint) override;
  void port_status(const port::PortStatusView& status, TimePoint) override;
  void explicit_reply(const std::string&, const rack::ExplicitAnswer&) override {}
  void bus_scan_reply(const std::string&, const port::BusScanAnswer&) override {}
  void port_stopped(const std::string& port) override;
  void node_removed(const std::string& port, devicenet::MacId mac) override;

  // prometheus::Collectable: the metric families now (the server's thread).
  std::vector<prometheus::MetricFamily> Collect() const override;

 private:
  struct NodeEntry {
    std::string name;
    std::uint64_t commands_accepted = 0;
    std::uint64_t commands_refused = 0;
    bool has_status = false;
    devicenet::NodeState state = devicenet::NodeState::kAbsent;
    devicenet::NodeCounters counters;
    devicenet::ExplicitCounters explicit_counters;
  };
  struct PortEntry {
    bool stopped = false;
    std::optional<port::PortStatusView> status;
    std::map<unsigned, NodeEntry> nodes;  // by MAC
  };

  // The node's name and command counters, into its entry (mutex_ held).
  NodeEntry& note_node(const std::string& port, const rack::NodeView& view);

  std::string rack_;
  std::function<ProcessCounters()> process_;
  mutable std::mutex mutex_;
  std::map<std::string, PortEntry> ports_;
};

// GET /metrics on `listen` ("HOST:PORT", IPv4; port 0, which the
// configuration refuses but tests use: any free one). Throws
// std::runtime_error if it cannot listen there.
class MetricsServer {
 public:
  MetricsServer(const std::string& listen, std::shared_ptr<RackMetrics> metrics);
  // The ports it listens on (the one chosen for port 0).
  std::vector<int> ports() const { return exposer_->GetListeningPorts(); }

 private:
  std::unique_ptr<prometheus::Exposer> exposer_;
  std::shared_ptr<RackMetrics> metrics_;
};

}  // namespace dnbridge::metrics
