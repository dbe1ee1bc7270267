// dnbridge-sim: dnbridge with the simulator linked in, for trying a
// configuration, demonstrations and tests: a port whose interface is
// "simulated" runs on an in-process bus of simulated CDN127s.
#include "adapters/daemon/bridge_main.hpp"
#include "adapters/daemon/simulated_backends.hpp"

int main(int argc, char** argv) {
  return dnbridge::daemon::bridge_main(
      argc, argv, {"dnbridge-sim", &dnbridge::daemon::simulated_backend_factory});
}
