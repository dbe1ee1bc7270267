#include "bridge/common/text.hpp"

namespace dnbridge {
namespace {

bool is_blank(char c) noexcept {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

char lower(char c) noexcept { return c >= 'A' && c <= 'Z' ? static_cast<char>(c + 32) : c; }

}  // namespace

std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

bool iequals(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

std::string to_lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = lower(c);
  return out;
}

bool has_hex_prefix(std::string_view s) noexcept {
  return s.size() >= 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
}

int hex_digit(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

HexBytes parse_hex_bytes(std::string_view text, std::string_view separators) {
  HexBytes out;
  int high = -1;  // the first digit of a byte, while waiting for the second
  for (char c : text) {
    if (separators.find(c) != std::string_view::npos) {
      if (high >= 0) {
        out.error = HexBytes::Error::kOneDigit;
        return out;
      }
      continue;
    }
    const int d = hex_digit(c);
    if (d < 0) {
      out.error = HexBytes::Error::kNotHexDigit;
      out.bad = c;
      return out;
    }
    if (high < 0) {
      high = d;
    } else {
      out.bytes.push_back(static_cast<std::uint8_t>(high * 16 + d));
      high = -1;
    }
  }
  if (high >= 0) out.error = HexBytes::Error::kOneDigit;
  return out;
}

}  // namespace dnbridge
