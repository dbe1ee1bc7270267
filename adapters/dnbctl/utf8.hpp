#pragma once
// The text dnbctl prints is UTF-8, as DDS carries it from the bridge (rack,
// port and node names from the rack's TOML file; device strings, ISO 8859-1
// on the wire, converted by the bridge). These read it code point by code
// point: for JSON, where a byte that is not UTF-8 becomes U+FFFD, and for
// tables, which align on the width a terminal gives each character.
#include <cstddef>
#include <string_view>

namespace dnbridge::dnbctl {

inline constexpr char32_t kReplacementCharacter = 0xFFFD;

// The code point at the start of `s` and the bytes it takes. A byte that
// does not begin a well-formed UTF-8 sequence (a stray continuation byte, a
// truncated or overlong sequence, a surrogate, beyond U+10FFFF) is
// U+FFFD of one byte. `s` must not be empty.
struct CodePoint {
  char32_t value;
  std::size_t length;
};
CodePoint next_code_point(std::string_view s) noexcept;

// Columns a terminal gives the code point: 0 for combining marks and other
// zero-width characters, 2 for East Asian wide and full-width characters and
// emoji, 1 otherwise (controls count 1: tables never hold them).
int column_width(char32_t c) noexcept;

// Columns of the whole text.
std::size_t display_width(std::string_view utf8) noexcept;

}  // namespace dnbridge::dnbctl
