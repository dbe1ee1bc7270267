// Pins Cyclone DDS to the loopback interface, without multicast, before any
// DDS call of the test process: tests never reach the real network. Each
// process has a domain id of its own and, in case two ids collide, a
// discovery tag of its own: test processes run in parallel (ctest -j, other
// checkouts on the machine) never discover one another.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "adapters/dds/loopback.hpp"
#include "dds_fixture.hpp"

namespace dnbridge::dds::testing {

dds_domainid_t test_domain() { return static_cast<dds_domainid_t>(100 + getpid() % 100); }

namespace {

// Unicast discovery needs a participant index per process and domain
// (Cyclone 0.10: 9 at most by default); 50 leaves room for several.
std::string loopback_config() {
  return dds::loopback_config("dnbridge-test-" + std::to_string(getpid()));
}

class LoopbackEnvironment : public ::testing::Environment {
 public:
  void SetUp() override { ASSERT_EQ(setenv("CYCLONEDDS_URI", loopback_config().c_str(), 1), 0); }
};

// gtest owns and runs it before the first test.
[[maybe_unused]] const auto* const kEnvironment =
    ::testing::AddGlobalTestEnvironment(new LoopbackEnvironment);

}  // namespace
}  // namespace dnbridge::dds::testing
