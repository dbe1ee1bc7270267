#pragma once
// Small text helpers for what people write: configuration values, command
// arguments, EDS files. ASCII only (case, digits, blanks).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dnbridge {

// `s` without the blanks (space, tab, CR, LF, FF, VT) at either end.
std::string_view trim(std::string_view s) noexcept;

// Equal ignoring ASCII case.
bool iequals(std::string_view a, std::string_view b) noexcept;
// `s` with ASCII letters in lower case.
std::string to_lower(std::string_view s);

// "0x" or "0X" first.
bool has_hex_prefix(std::string_view s) noexcept;
// 0..15, or -1 for a character that is not a hex digit.
int hex_digit(char c) noexcept;

// Bytes written as pairs of hex digits, pairs side by side or apart by any
// of `separators` ("20 04 24 01", "200424:01").
struct HexBytes {
  enum class Error : std::uint8_t { kNone, kOneDigit, kNotHexDigit };
  std::vector<std::uint8_t> bytes;
  Error error = Error::kNone;
  char bad = 0;  // kNotHexDigit: the character
};
HexBytes parse_hex_bytes(std::string_view text, std::string_view separators);

}  // namespace dnbridge
