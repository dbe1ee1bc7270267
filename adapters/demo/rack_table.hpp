#pragma once
// The demo's view of a rack: one line per pump with its state and I/O.
#include <deque>
#include <string>

#include "adapters/sim/world/sim_rack.hpp"

namespace dnbridge::demo {

std::string render_rack(sim::SimRack& rack, TimePoint started,
                        const std::deque<std::string>& events);

}  // namespace dnbridge::demo
