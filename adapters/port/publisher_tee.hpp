#pragma once
// One port's publications to two publishers, in order (the metrics, then
// the DDS face). Each gets every call, on the port's thread.
#include "adapters/port/port_publisher.hpp"

namespace dnbridge::port {

class PublisherTee final : public PortPublisher {
 public:
  PublisherTee(PortPublisher& first, PortPublisher& second) : first_(first), second_(second) {}

  void node_state(const std::string& port, const rack::NodeView& node,
                  TimePoint source_time) override {
    first_.node_state(port, node, source_time);
    second_.node_state(port, node, source_time);
  }
  void node_status(const std::string& port, const rack::NodeView& node,
                   const NodeStatusView& status, TimePoint source_time) override {
    first_.node_status(port, node, status, source_time);
    second_.node_status(port, node, status, source_time);
  }
  void port_status(const PortStatusView& status, TimePoint source_time) override {
    first_.port_status(status, source_time);
    second_.port_status(status, source_time);
  }
  void explicit_reply(const std::string& port, const rack::ExplicitAnswer& answer) override {
    first_.explicit_reply(port, answer);
    second_.explicit_reply(port, answer);
  }
  void bus_scan_reply(const std::string& port, const BusScanAnswer& answer) override {
    first_.bus_scan_reply(port, answer);
    second_.bus_scan_reply(port, answer);
  }
  void port_stopped(const std::string& port) override {
    first_.port_stopped(port);
    second_.port_stopped(port);
  }
  void node_removed(const std::string& port, devicenet::MacId mac) override {
    first_.node_removed(port, mac);
    second_.node_removed(port, mac);
  }

 private:
  PortPublisher& first_;
  PortPublisher& second_;
};

}  // namespace dnbridge::port
