#include "adapters/port/node_publication.hpp"

#include <algorithm>
#include <bit>
#include <utility>

namespace dnbridge::port {

using devicenet::MacId;

namespace {

bool listed(const std::vector<MacId>& macs, MacId mac) {
  return std::find(macs.begin(), macs.end(), mac) != macs.end();
}

rack::PublishPolicy policy_of(const NodePublication::Policies& policies, MacId mac) {
  const auto it = policies.find(mac);
  return it == policies.end() ? rack::PublishPolicy{} : it->second;
}

}  // namespace

NodePublication::Carried NodePublication::carry(const rack::RackPort& port,
                                                const rack::ScanListChange& sc,
                                                const Policies& policies) {
  Carried carried;
  for (std::size_t m = 0; m < kMacs; ++m) {
    const MacId mac = *MacId::from(static_cast<unsigned>(m));
    auto& p = published_[m];
    const rack::ProfileNodes* nodes = port.nodes_of(mac);
    if (!nodes) {
      p.reset();
      due_[m] = kNever;
      continue;
    }
    const rack::PublishPolicy policy = policy_of(policies, mac);
    if (!p || listed(sc.added, mac) || listed(sc.reconfigured, mac)) {
      p.emplace(Published{nodes->state_gate(policy)});
      fresh_ |= std::uint64_t{1} << m;
      carried.fresh.push_back(mac);
    } else if (!(p->gate->policy() == policy)) {
      // A new gate has published nothing: it is asked at the next pass and
      // its period runs from there, changed or not.
      p->gate = nodes->state_gate(policy);
      p->checked = ~0ull;
      fresh_ |= std::uint64_t{1} << m;
      carried.policy_changed.push_back(mac);
    }
    note_due(m);
  }
  next_due_ = *std::min_element(due_.begin(), due_.end());
  return carried;
}

void NodePublication::publish(rack::RackPort& port, TimePoint now, bool force) {
  std::uint64_t look = port.take_changed() | std::exchange(fresh_, 0);
  if (force || now >= next_due_) look |= due_at(now, force);
  while (look != 0) {
    const auto m = static_cast<std::size_t>(std::countr_zero(look));
    look &= look - 1;
    const MacId mac = *MacId::from(static_cast<unsigned>(m));
    const rack::ProfileNodes* nodes = port.nodes_of(mac);
    // A node removed since it was marked.
    if (!nodes || !published_[m]) continue;
    publish_node(port, *nodes->node(mac), *published_[m], now, force);
    note_due(m);
  }
  next_due_ = *std::min_element(due_.begin(), due_.end());
}

void NodePublication::publish_node(const rack::RackPort& port, const rack::NodeView& v,
                                   Published& p, TimePoint now, bool force) {
  // The source time is that of the latest event the sample reflects; a
  // node nothing has happened to yet has been absent since the loop started.
  TimePoint source = std::max(v.state_since, started_);
  if (v.has_inputs) source = std::max(source, v.inputs_time);
  // Unchanged since the gate was last asked, a node is due only by time.
  if (force || v.changes != p.checked || now >= p.gate->deadline()) {
    p.checked = v.changes;
    if (force || p.gate->due(v, now)) {
      publisher_.node_state(port_, v, source);
      p.gate->published(v, now);
    }
  }
  if (force || !p.status_once || v.status_changes != p.changes ||
      now >= p.status_time + status_period_) {
    publisher_.node_status(port_, v, NodeStatusView::of(*port.scanner().node(v.mac)),
                           std::max(source, p.status_time));
    p.changes = v.status_changes;
    p.status_time = now;
    p.status_once = true;
  }
}

TimePoint NodePublication::due_of(const Published& p) const {
  // Before its first NodeStatus a node is published at the next pass
  // (fresh_), not by time.
  const TimePoint status = p.status_once ? p.status_time + status_period_ : kNever;
  return std::min(p.gate->deadline(), status);
}

void NodePublication::note_due(std::size_t mac) {
  due_[mac] = published_[mac] ? due_of(*published_[mac]) : kNever;
}

std::uint64_t NodePublication::due_at(TimePoint now, bool all) const {
  std::uint64_t due = 0;
  for (std::size_t m = 0; m < kMacs; ++m) {
    if (published_[m] && (all || now >= due_[m])) due |= std::uint64_t{1} << m;
  }
  return due;
}

}  // namespace dnbridge::port
