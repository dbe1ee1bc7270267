#pragma once
// What every dnbctl command shares: the global options, the exit codes, and
// the error that ends a command with one of them.
#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "adapters/security/settings.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::dnbctl {

// Exit codes (documented in --help).
enum class Exit : int {
  kOk = 0,
  kFailed = 1,    // the operation failed: refused, not applied, device error status
  kUsage = 2,     // a bad command line
  kNotFound = 3,  // no bridge or node answered within the timeout
};

// Ends a command: main() prints the sentence on stderr and exits with `code`.
// dnbctl is a program at the edge: its commands stop by throwing this rather
// than threading a status through every helper.
class CommandError : public std::runtime_error {
 public:
  CommandError(Exit code, const std::string& sentence)
      : std::runtime_error(sentence), code_(code) {}
  Exit code() const noexcept { return code_; }

 private:
  Exit code_;
};

struct GlobalOptions {
  std::uint32_t domain = 0;
  std::string rack;  // empty: any rack
  std::string port;  // empty: any port
  double timeout_seconds = 3.0;
  bool json = false;
  // DDS Security of dnbctl's participant (--security FILE, checked); none:
  // Cyclone's XML configuration decides (CYCLONEDDS_URI).
  std::optional<security::Settings> security;

  Duration timeout() const {
    return std::chrono::duration_cast<Duration>(std::chrono::duration<double>(timeout_seconds));
  }
  bool matches(std::string_view rack_name, std::string_view port_name) const {
    return (rack.empty() || rack == rack_name) && (port.empty() || port == port_name);
  }
};

// A bound on a wait, on the steady clock.
using Deadline = std::chrono::steady_clock::time_point;
inline Deadline deadline_after(Duration d) { return std::chrono::steady_clock::now() + d; }

}  // namespace dnbridge::dnbctl
