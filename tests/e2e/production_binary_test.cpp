// dnbridge, the production program, carries no simulator: it refuses
// --simulate and a port on the simulated bus, saying that dnbridge-sim runs
// them. (tests/tools/check_no_simulator.cmake checks its symbols.)
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "bridge_process.hpp"
#include "child_process.hpp"

namespace dnbridge::e2e {
namespace {

// Runs `args` to its end (at most 20 s): its exit code and what it wrote on stderr.
std::pair<std::optional<int>, std::string> run(std::vector<std::string> args) {
  ChildOptions options;
  options.capture_stderr = true;
  ChildProcess child(std::move(args), options);
  const auto code = child.wait_for(std::chrono::seconds(20));
  std::string err;
  char buf[4096];
  for (ssize_t n; (n = ::read(child.stderr_fd(), buf, sizeof buf)) > 0;) {
    err.append(buf, static_cast<std::size_t>(n));
  }
  return {code, err};
}

TEST(ProductionBinary, RefusesToSimulate) {
  const auto [code, err] = run({DNBRIDGE_PRODUCTION_BINARY, "--simulate"});
  EXPECT_EQ(code, 2);
  EXPECT_NE(err.find("carries no simulator: dnbridge-sim runs the simulated rack"),
            std::string::npos)
      << err;
}

TEST(ProductionBinary, RefusesAPortOnTheSimulatedBus) {
  const auto config = write_simulated_rack_config(dds::testing::test_domain());
  const auto [code, err] = run({DNBRIDGE_PRODUCTION_BINARY, "--config", config.string()});
  std::filesystem::remove(config);
  EXPECT_EQ(code, 1);
  EXPECT_NE(err.find("port A: interface \"simulated\" is the simulator's bus, and this program "
                     "carries no simulator: dnbridge-sim runs it"),
            std::string::npos)
      << err;
}

TEST(ProductionBinary, ChecksASimulatedRackAsAConfiguration) {
  // The file itself is valid: dnbridge-sim runs it, and --check-config says so.
  const auto config = write_simulated_rack_config(dds::testing::test_domain());
  const auto [code, err] = run({DNBRIDGE_PRODUCTION_BINARY, "--check-config", config.string()});
  std::filesystem::remove(config);
  EXPECT_EQ(code, 0) << err;
}

}  // namespace
}  // namespace dnbridge::e2e
