#pragma once
// A scripted day in the life of a rack, for the demo: supervisors command
// pumps, a pump trips on its interlock, one loses power, one loses its
// commander. Each step is applied at its time through the same calls a real
// supervisor and the simulated hardware use.
#include <functional>
#include <string>
#include <vector>

#include "adapters/sim/world/sim_rack.hpp"

namespace dnbridge::demo {

struct ScenarioStep {
  Duration at;  // since the rack started
  std::string what;
  std::function<void(sim::SimRack&, TimePoint now)> apply;
};

// Steps for a rack whose pumps have MACs `macs`; repeats every `period`.
std::vector<ScenarioStep> make_scenario(const std::vector<unsigned>& macs);
Duration scenario_period();

}  // namespace dnbridge::demo
