#pragma once
// A port's nodes' samples: each node's state, when its profile's gate says
// it is news or its maximum period is due (publish_gate.hpp), and its
// NodeStatus, on a change of status or once per status period.
//
// Pushed by the nodes' changes: the rack marks every node whose view changes
// (rack::RackPort::take_changed), and a pass looks at the marked nodes and
// at those whose period is due, no others. For each of those the rules are
// the ones a look at every node would apply: the view's change counters
// against what was last published, and the periods.
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "adapters/port/port_publisher.hpp"
#include "bridge/common/time.hpp"
#include "bridge/rack/publish_gate.hpp"
#include "bridge/rack/rack_port.hpp"

namespace dnbridge::port {

class NodePublication {
 public:
  using Policies = std::map<devicenet::MacId, rack::PublishPolicy>;

  NodePublication(std::string port, Duration status_period, PortPublisher& publisher)
      : port_(std::move(port)), status_period_(status_period), publisher_(publisher) {}

  // The loop's start: a node nothing has happened to yet has been absent
  // since then (its samples' source time).
  void start(TimePoint now) { started_ = now; }

  // What is kept of each node after the scan list changed by `sc` (a
  // reload; at start, every node added): a node kept keeps what was
  // published of it, with a new gate if its policy in `policies` changed; a
  // new or configured again one starts afresh and is published at the next
  // pass; a removed one goes.
  struct Carried {
    std::vector<devicenet::MacId> fresh;           // added, configured again
    std::vector<devicenet::MacId> policy_changed;  // kept, with a new gate
  };
  Carried carry(const rack::RackPort& port, const rack::ScanListChange& sc,
                const Policies& policies);

  // Publishes what is due of the nodes `port` marked changed and of those
  // whose period is due; of every node when `force`.
  void publish(rack::RackPort& port, TimePoint now, bool force);

  // When a pass next has something to do without a change of a node: the
  // earliest gate deadline or status period of any node. kNever: none.
  TimePoint next_due() const { return next_due_; }

 private:
  // What was published of a node.
  struct Published {
    std::unique_ptr<rack::StateGate> gate;  // its profile's (ProfileNodes::state_gate)
    std::uint64_t checked = ~0ull;          // the view's changes when the gate was last asked
    std::uint64_t changes = ~0ull;          // the view's status_changes at the last NodeStatus
    TimePoint status_time{};
    bool status_once = false;
  };
  static constexpr std::size_t kMacs = devicenet::MacId::kMax + 1;

  void publish_node(const rack::RackPort& port, const rack::NodeView& v, Published& p,
                    TimePoint now, bool force);
  // When the node's gate or status period is next due; kNever for none.
  TimePoint due_of(const Published& p) const;
  // The nodes whose period is due at `now` (every node when `all`), a bit
  // per MAC.
  std::uint64_t due_at(TimePoint now, bool all) const;
  void note_due(std::size_t mac);

  std::string port_;
  Duration status_period_;
  PortPublisher& publisher_;
  TimePoint started_{};
  // By MAC, for every node of the scan list.
  std::array<std::optional<Published>, kMacs> published_;
  std::array<TimePoint, kMacs> due_{};  // due_of each, kNever for none
  std::uint64_t fresh_ = 0;             // new since the last pass, a bit per MAC
  TimePoint next_due_ = kNever;
};

}  // namespace dnbridge::port
