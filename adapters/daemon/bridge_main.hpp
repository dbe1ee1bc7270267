#pragma once
// The bridge's command line and life: parses the options, loads and checks
// the configuration, runs a Daemon until SIGINT or SIGTERM. Two programs
// share it: dnbridge (SocketCAN ports only: it carries no simulator code)
// and dnbridge-sim (the same, with the simulator's in-process bus for ports
// whose interface is "simulated", and --simulate).
#include <string_view>

#include "adapters/daemon/daemon.hpp"

namespace dnbridge::daemon {

struct Program {
  std::string_view name;  // as --help and --version say it
  // The simulator's backends (simulated_backend_factory), or null.
  BackendFactory (*simulated_backends)(LogSink& log) = nullptr;
};

// Exit codes: 0 stopped in order; 1 failed while running or at set-up;
// 2 bad command line or configuration.
int bridge_main(int argc, char** argv, const Program& program);

}  // namespace dnbridge::daemon
