#pragma once
// A device's health as its Identity object tells it: Status (attribute 5)
// fault bits and State (attribute 8). The ODVA numbering of the bits is used
// (8 minor recoverable, 9 minor unrecoverable, 10 major recoverable, 11 major
// unrecoverable); the CDN127 manual lists its bits 8 and 9 twice.
#include <cstdint>
#include <optional>
#include <string>

namespace dnbridge::cip::identity {

inline constexpr std::uint16_t kMinorRecoverableFault = 1u << 8;
inline constexpr std::uint16_t kMinorUnrecoverableFault = 1u << 9;
inline constexpr std::uint16_t kMajorRecoverableFault = 1u << 10;
inline constexpr std::uint16_t kMajorUnrecoverableFault = 1u << 11;

inline constexpr std::uint8_t kStateOperational = 3;
inline constexpr std::uint8_t kStateMajorRecoverableFault = 4;
inline constexpr std::uint8_t kStateMajorUnrecoverableFault = 5;

// "major recoverable fault (Identity.Status 0x0400, State 4)", or nothing
// when neither what was read of Status nor of State says so.
std::optional<std::string> major_fault(std::optional<std::uint16_t> status,
                                       std::optional<std::uint8_t> state);
// "minor recoverable fault (Identity.Status 0x0100)", or empty.
std::string minor_faults(std::uint16_t status);

}  // namespace dnbridge::cip::identity
