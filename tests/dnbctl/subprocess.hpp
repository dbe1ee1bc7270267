#pragma once
// Runs a program as a child process, with this process's environment, and
// collects its exit code, stdout and stderr. A child that outlives
// `timeout` is killed (and reported as exit code -1): a hung client fails
// the test instead of hanging it. Children may be run from several threads
// at once.
#include <chrono>
#include <string>
#include <vector>

namespace dnbridge::dnbctl::testing {

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

RunResult run(const std::string& program, const std::vector<std::string>& args,
              std::chrono::milliseconds timeout = std::chrono::seconds(15));

}  // namespace dnbridge::dnbctl::testing
