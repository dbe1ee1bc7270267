#include "adapters/port/port_reconfiguration.hpp"

#include <fmt/format.h>

#include <array>
#include <exception>
#include <vector>

namespace dnbridge::port {

using devicenet::MacId;

void PortReconfiguration::start(const PortLoopConfig& in_force) {
  rack::ScanListChange all;
  for (const rack::ProfileNodes* nodes : port_.profiles()) {
    for (std::size_t i = 0; i < nodes->size(); ++i) all.added.push_back(nodes->view(i).mac);
  }
  for (MacId mac : publication_.carry(port_, all, in_force.publish).fresh) metrics_.restart(mac);
}

PortChange PortReconfiguration::apply(PortLoopConfig& in_force, PortLoopConfig& next,
                                      rack::ExplicitGateway& gateway, TimePoint now) {
  PortChange change;
  std::array<std::string_view, MacId::kMax + 1> profile_before{};
  for (unsigned m = 0; m <= MacId::kMax; ++m) {
    if (const rack::ProfileNodes* nodes = port_.nodes_of(*MacId::from(m))) {
      profile_before[m] = nodes->profile();
    }
  }
  try {
    change.scan_list = port_.reconfigure(next.scanner, next.nodes, now);
  } catch (const std::exception& e) {
    change.refused = e.what();
    log_.error("configuration not applied: {}", change.refused);
    return change;
  }
  in_force.nodes = std::move(next.nodes);
  in_force.publish = std::move(next.publish);
  auto carried = publication_.carry(port_, change.scan_list, in_force.publish);
  for (MacId mac : carried.fresh) metrics_.restart(mac);
  change.publish_changed = std::move(carried.policy_changed);
  dispose(in_force.port, change.scan_list, profile_before);
  if (!(gateway.policy() == next.explicit_policy)) {
    gateway.set_policy(next.explicit_policy);
    change.explicit_policy_changed = true;
  }
  in_force.explicit_policy = next.explicit_policy;
  if (change.any()) log_change(change);
  return change;
}

void PortReconfiguration::dispose(const std::string& port, const rack::ScanListChange& sc,
                                  const std::array<std::string_view, MacId::kMax + 1>& before) {
  for (MacId mac : sc.removed) publisher_.node_removed(port, mac);
  for (MacId mac : sc.reconfigured) {
    const rack::ProfileNodes* nodes = port_.nodes_of(mac);
    if (!nodes || nodes->profile() != before[mac.value()]) publisher_.node_removed(port, mac);
  }
}

void PortReconfiguration::log_change(const PortChange& change) {
  const auto macs = [](const std::vector<MacId>& list) {
    std::string s;
    for (MacId m : list) s += fmt::format("{}{}", s.empty() ? "" : " ", m.value());
    return s.empty() ? std::string("none") : s;
  };
  const rack::ScanListChange& sc = change.scan_list;
  log_.info(
      "configuration applied: added {}; removed {}; configured again {}; policies changed {}; "
      "publish policies changed {}; untouched {}{}{}",
      macs(sc.added), macs(sc.removed), macs(sc.reconfigured), macs(sc.updated),
      macs(change.publish_changed), macs(sc.unchanged),
      sc.timings_changed ? "; the port's timings changed" : "",
      change.explicit_policy_changed ? "; the explicit policy changed" : "");
}

}  // namespace dnbridge::port
