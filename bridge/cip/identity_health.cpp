#include "bridge/cip/identity_health.hpp"

#include <fmt/format.h>

namespace dnbridge::cip::identity {
namespace {

// The values that say so (Status with a major fault bit, State 4 or 5): the
// two are read at different times, and the other may be older.
std::string read_values(std::optional<std::uint16_t> status, std::optional<std::uint8_t> state) {
  std::string s;
  if (status && (*status & (kMajorRecoverableFault | kMajorUnrecoverableFault)) != 0)
    s = fmt::format("Identity.Status 0x{:04X}", *status);
  if (state == kStateMajorRecoverableFault || state == kStateMajorUnrecoverableFault)
    s += fmt::format("{}Identity.State {}", s.empty() ? "" : ", ", *state);
  return s;
}

}  // namespace

std::optional<std::string> major_fault(std::optional<std::uint16_t> status,
                                       std::optional<std::uint8_t> state) {
  const std::uint16_t bits = status.value_or(0);
  const bool unrecoverable =
      (bits & kMajorUnrecoverableFault) != 0 || state == kStateMajorUnrecoverableFault;
  const bool recoverable =
      (bits & kMajorRecoverableFault) != 0 || state == kStateMajorRecoverableFault;
  if (!unrecoverable && !recoverable) return std::nullopt;
  return fmt::format("{} ({})",
                     unrecoverable ? "major unrecoverable fault: only a power cycle clears it"
                                   : "major recoverable fault",
                     read_values(status, state));
}

std::string minor_faults(std::uint16_t status) {
  const bool recoverable = (status & kMinorRecoverableFault) != 0;
  const bool unrecoverable = (status & kMinorUnrecoverableFault) != 0;
  if (!recoverable && !unrecoverable) return {};
  return fmt::format("{}{}{} (Identity.Status 0x{:04X})",
                     recoverable ? "minor recoverable fault" : "",
                     recoverable && unrecoverable ? ", " : "",
                     unrecoverable ? "minor unrecoverable fault" : "", status);
}

}  // namespace dnbridge::cip::identity
