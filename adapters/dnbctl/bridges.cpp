#include "adapters/dnbctl/bridges.hpp"

namespace dnbridge::dnbctl {
namespace {

constexpr dds::WaitSet::Token kDiscovery = 20;

}  // namespace

Bridges::Bridges(Client& client) : reader_(client.participant()), data_(reader_, DDS_ANY_STATE) {
  client.attach(data_, kDiscovery);
}

void Bridges::refresh() {
  auto news = reader_.take();
  if (!news) return;
  for (auto& p : *news) {
    auto it = seen_.find(p.guid);
    if (it != seen_.end()) {
      it->second.alive = p.alive;  // a bridge that left (or, rarely, came back)
      continue;
    }
    if (auto rack = dds::bridge_rack(p.name); rack && p.alive) {
      seen_.emplace(p.guid, Seen{std::move(*rack), true});
    }
  }
}

std::map<std::string, unsigned> Bridges::live() const {
  std::map<std::string, unsigned> racks;
  for (const auto& [guid, s] : seen_) {
    if (s.alive) ++racks[s.rack];
  }
  return racks;
}

}  // namespace dnbridge::dnbctl
