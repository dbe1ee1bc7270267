// Pins Cyclone DDS to the loopback interface, without multicast, before any
// DDS call of the test process: tests never reach the real network.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>

#include "dds_fixture.hpp"

namespace dnbridge::dds::testing {

dds_domainid_t test_domain() { return static_cast<dds_domainid_t>(100 + getpid() % 100); }

namespace {

constexpr const char* kLoopbackConfig =
    "<CycloneDDS><Domain><General>"
    "<Interfaces><NetworkInterface name=\"lo\"/></Interfaces>"
    "<AllowMulticast>false</AllowMulticast>"
    "</General><Discovery>"
    "<ParticipantIndex>auto</ParticipantIndex>"
    "<MaxAutoParticipantIndex>50</MaxAutoParticipantIndex>"
    "<Peers><Peer address=\"127.0.0.1\"/></Peers>"
    "</Discovery></Domain></CycloneDDS>";

class LoopbackEnvironment : public ::testing::Environment {
 public:
  void SetUp() override { ASSERT_EQ(setenv("CYCLONEDDS_URI", kLoopbackConfig, 1), 0); }
};

// gtest owns and runs it before the first test.
[[maybe_unused]] const auto* const kEnvironment =
    ::testing::AddGlobalTestEnvironment(new LoopbackEnvironment);

}  // namespace
}  // namespace dnbridge::dds::testing
