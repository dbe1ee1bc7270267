#include "adapters/dnbctl/bridges.hpp"

#include <algorithm>

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
      const std::string host = dds::user_data_field(p.user_data, "host");
      const std::string pid = dds::user_data_field(p.user_data, "pid");
      std::string where = host;
      if (!pid.empty()) where += (host.empty() ? "? (pid " : " (pid ") + pid + ")";
      // Another program's text: no control character reaches a table.
      for (char& c : where) {
        if (static_cast<unsigned char>(c) < 0x20 || c == '\x7F') c = '?';
      }
      seen_.emplace(p.guid, Seen{std::move(*rack), std::move(where), true});
    }
  }
}

std::map<std::string, std::vector<std::string>> Bridges::live() const {
  std::map<std::string, std::vector<std::string>> racks;
  for (const auto& [guid, s] : seen_) {
    if (s.alive) racks[s.rack].push_back(s.where);
  }
  for (auto& [rack, where] : racks) std::sort(where.begin(), where.end());
  return racks;
}

}  // namespace dnbridge::dnbctl
