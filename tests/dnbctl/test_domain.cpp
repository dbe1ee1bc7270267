#include "test_domain.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "adapters/dds/loopback.hpp"

namespace dnbridge::dnbctl::testing {
namespace {

// Set before any DDS call of the process; dnbctl children inherit it.
class LoopbackEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    const std::string xml = dds::loopback_config("dnbctl-test-" + std::to_string(getpid()));
    ASSERT_EQ(setenv("CYCLONEDDS_URI", xml.c_str(), 1), 0);
  }
};
[[maybe_unused]] const auto* const kEnvironment =
    ::testing::AddGlobalTestEnvironment(new LoopbackEnvironment);

}  // namespace

std::uint32_t test_domain() { return static_cast<std::uint32_t>(100 + getpid() % 100); }

}  // namespace dnbridge::dnbctl::testing
