#pragma once
// The simulator's backends for the daemon, in a library of their own
// (dnbridge::daemon_sim) that dnbridge-sim, the tests and the benchmarks
// link, and dnbridge does not.
#include "adapters/daemon/daemon.hpp"

namespace dnbridge::daemon {

// Interface "simulated": the in-process simulated bus at the port's bit
// rate, with a CDN127 at each configured node, powered on at once. Any
// other interface: default_backend_factory's.
BackendFactory simulated_backend_factory(LogSink& log);

}  // namespace dnbridge::daemon
