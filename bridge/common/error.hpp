#pragma once
// Error codes of the protocol core. Codecs and state machines report failures
// as values (Result<T>), never by throwing.
#include <string>
#include <system_error>

namespace dnbridge {

enum class Errc {
  kTruncated = 1,      // input ended before a complete field
  kMalformed,          // a field's value makes the input meaningless
  kOutOfRange,         // a value outside what the protocol or device allows
  kBufferTooSmall,     // the caller's output span cannot hold the encoding
  kUnsupported,        // valid on the wire but not handled here
  kInvalidIdentifier,  // a CAN identifier outside the DeviceNet groups
  kBusy,               // a resource already in use (queue full, transaction pending)
  kTimeout,            // an awaited frame did not arrive in time
  kAborted,            // a transfer was given up (e.g. fragment ack missing twice)
  kNotConnected,       // no connection to the device
  kDeviceError,        // the device answered with a CIP error status
  kStopped,            // the port or master is stopped
};

const std::error_category& dnbridge_category() noexcept;

inline std::error_code make_error_code(Errc e) noexcept {
  return {static_cast<int>(e), dnbridge_category()};
}

}  // namespace dnbridge

template <>
struct std::is_error_code_enum<dnbridge::Errc> : std::true_type {};
