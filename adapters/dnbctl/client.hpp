#pragma once
// dnbctl's side of DDS: one participant with readers of the state topics
// (PumpState, DeviceState, NodeStatus, PortStatus), whose latest sample per
// instance is kept here; writers of PumpCommand and ExplicitRequest are made
// by the commands that need them (commander.hpp, requester.hpp). All QoS
// come from adapters/dds/topics.hpp, the contract the bridge uses too.
#include <compare>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topic.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dnbctl/options.hpp"

namespace dnbridge::dnbctl {

struct NodeKey {
  std::string rack;
  std::string port;
  std::uint8_t mac = 0;
  auto operator<=>(const NodeKey&) const = default;
};

struct PortKey {
  std::string rack;
  std::string port;
  auto operator<=>(const PortKey&) const = default;
};

// The latest sample of one instance.
template <class T>
struct Known {
  dds::Owned<T> data;
  // False once the bridge that wrote it is gone (no writer left): the
  // sample is its last word, not the current state.
  bool alive = true;
  std::uint64_t samples =
      0;  // valid samples received: a new one since a moment shows as an increase
};

// SIGINT and SIGTERM end waits (watch, --hold-for) instead of the process.
void install_interrupt_handlers();
bool interrupted() noexcept;

class Client {
 public:
  // Joins `domain` as participant `name` (e.g. "dnbctl user@host:pid"),
  // with `properties` (DDS Security's). Throws dds::Error.
  Client(std::uint32_t domain, const std::string& name, const dds::Properties& properties = {});

  const dds::Participant& participant() const noexcept { return participant_; }

  // Takes what arrived into the caches; `on_pump` is called for every valid
  // PumpState sample, in arrival order (watch prints them), and when a
  // known pump's bridge leaves (alive turns false).
  void refresh(
      const std::function<void(const NodeKey&, const Known<dnbridge_PumpState>&)>& on_pump = {});

  // Waits until something attached has data, `timeout` passes, or an
  // interrupt (then at most 100 ms late). Then refresh() is due.
  void wait(Duration timeout);

  // refresh() and wait() until `done()` holds (true), the deadline passes
  // or an interrupt comes (false).
  bool wait_until(Deadline deadline, const std::function<bool()>& done);

  // Other readers (of replies) wake wait() too; `token` is not 0.
  void attach(const dds::Entity& entity, dds::WaitSet::Token token) {
    waitset_.attach(entity, token);
  }

  const std::map<NodeKey, Known<dnbridge_PumpState>>& pumps() const noexcept { return pumps_; }
  const std::map<NodeKey, Known<dnbridge_DeviceState>>& devices() const noexcept {
    return devices_;
  }
  const std::map<NodeKey, Known<dnbridge_NodeStatus>>& nodes() const noexcept { return nodes_; }
  const std::map<PortKey, Known<dnbridge_PortStatus>>& ports() const noexcept { return ports_; }

  const Known<dnbridge_PumpState>* pump(const NodeKey& key) const;
  const Known<dnbridge_DeviceState>* device(const NodeKey& key) const;
  const Known<dnbridge_NodeStatus>* node(const NodeKey& key) const;

 private:
  dds::Participant participant_;
  dds::Topic<dnbridge_PumpState> pump_topic_;
  dds::Topic<dnbridge_NodeStatus> node_topic_;
  dds::Topic<dnbridge_PortStatus> port_topic_;
  dds::Reader<dnbridge_PumpState> pump_reader_;
  dds::Reader<dnbridge_NodeStatus> node_reader_;
  dds::Reader<dnbridge_PortStatus> port_reader_;
  dds::ReadCondition pump_data_;
  dds::ReadCondition node_data_;
  dds::ReadCondition port_data_;
  dds::WaitSet waitset_;
  // DeviceState; none when DDS Security does not grant it (permissions
  // signed before the topic came): devices are then not shown.
  struct DevicesIn {
    explicit DevicesIn(const dds::Participant& participant);
    dds::Topic<dnbridge_DeviceState> topic;
    dds::Reader<dnbridge_DeviceState> reader;
    dds::ReadCondition data;
  };
  std::optional<DevicesIn> devices_in_;
  std::map<NodeKey, Known<dnbridge_PumpState>> pumps_;
  std::map<NodeKey, Known<dnbridge_DeviceState>> devices_;
  std::map<NodeKey, Known<dnbridge_NodeStatus>> nodes_;
  std::map<PortKey, Known<dnbridge_PortStatus>> ports_;
};

// "user@host": who runs dnbctl, for issuers and requester names.
std::string user_at_host();
std::string host_name();

}  // namespace dnbridge::dnbctl
