#include "adapters/dnbctl/values.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include "bridge/cip/data_types.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/text.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"

namespace dnbridge::dnbctl {
namespace {

// Digits of one number as parse_unsigned reads it: decimal, or hex with 0x
// (whether it fits is parse_unsigned's to say).
bool is_number(std::string_view s) {
  const bool hex = has_hex_prefix(s);
  if (hex) s.remove_prefix(2);
  return !s.empty() && std::all_of(s.begin(), s.end(), [hex](char c) {
    return hex ? hex_digit(c) >= 0 : (c >= '0' && c <= '9');
  });
}

}  // namespace

Parsed<std::uint64_t> parse_unsigned(std::string_view text, std::uint64_t max,
                                     std::string_view what) {
  const std::string_view t = trim(text);
  std::string_view digits = t;
  int base = 10;
  if (has_hex_prefix(digits)) {
    digits.remove_prefix(2);
    base = 16;
  }
  std::uint64_t value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value, base);
  if (digits.empty() || end != digits.data() + digits.size() ||
      (ec != std::errc{} && ec != std::errc::result_out_of_range)) {
    return Parsed<std::uint64_t>::failure(
        fmt::format("{} \"{}\" is not a number (decimal, or hex with 0x)", what, text));
  }
  if (ec == std::errc::result_out_of_range || value > max) {
    return Parsed<std::uint64_t>::failure(fmt::format("{} {} is out of range 0..{}", what, t, max));
  }
  return value;
}

Parsed<std::uint8_t> parse_mac(std::string_view text) {
  auto v = parse_unsigned(text, 63, "MAC ID");
  if (!v) return Parsed<std::uint8_t>::failure(v.error());
  return static_cast<std::uint8_t>(*v);
}

Parsed<NodeRef> parse_node(std::string_view text) {
  const std::string t(trim(text));
  if (t.empty())
    return Parsed<NodeRef>::failure("no node given: a MAC ID (0..63) or a node's name");
  // A number (decimal, or hex with 0x) is a MAC ID, and out of range is an
  // error, never a name; anything else ("3-dry-pump") is a name.
  if (is_number(t)) {
    auto mac = parse_mac(t);
    if (!mac) return Parsed<NodeRef>::failure(mac.error());
    return NodeRef{*mac, {}};
  }
  return NodeRef{std::nullopt, t};
}

Parsed<bool> parse_on_off(std::string_view text) {
  const std::string t = to_lower(trim(text));
  if (t == "on" || t == "1" || t == "true") return true;
  if (t == "off" || t == "0" || t == "false") return false;
  return Parsed<bool>::failure(fmt::format("\"{}\" is neither on nor off", text));
}

Parsed<AnalogValue> parse_analog(std::string_view text) {
  using profiles::cdn127::kAnalogFullScaleVolts;
  using profiles::cdn127::kAnalogMaxRaw;
  std::string_view t = trim(text);
  if (!t.empty() && (t.back() == 'V' || t.back() == 'v')) {
    t.remove_suffix(1);
    t = trim(t);
    double volts = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), volts);
    if (t.empty() || ec != std::errc{} || end != t.data() + t.size() || !std::isfinite(volts)) {
      return Parsed<AnalogValue>::failure(
          fmt::format("analog value \"{}\" is not a voltage such as 5.0V", text));
    }
    // The profile refuses what is outside 0..10 V; the sentence is ours.
    auto raw = profiles::cdn127::volts_to_raw(volts);
    if (!raw) {
      return Parsed<AnalogValue>::failure(
          fmt::format("analog value {} V is out of range 0..{} V", t, kAnalogFullScaleVolts));
    }
    return AnalogValue{*raw, volts};
  }
  // No suffix: a raw count. A decimal point without V is a likely slip
  // ("5.0" meant as volts): refuse it rather than guess.
  if (t.find('.') != std::string_view::npos) {
    return Parsed<AnalogValue>::failure(
        fmt::format("analog value \"{}\": give volts with a V suffix (5.0V) or a raw count 0..{}",
                    text, kAnalogMaxRaw));
  }
  if (!t.empty() && t.front() == '-') {
    return Parsed<AnalogValue>::failure(
        fmt::format("analog value {} is out of range 0..{} (raw)", t, kAnalogMaxRaw));
  }
  auto raw = parse_unsigned(t, kAnalogMaxRaw, "raw analog value");
  if (!raw) return Parsed<AnalogValue>::failure(raw.error());
  return AnalogValue{static_cast<std::uint16_t>(*raw), std::nullopt};
}

Parsed<std::vector<std::uint8_t>> parse_hex_bytes(std::string_view text) {
  std::string_view t = trim(text);
  if (has_hex_prefix(t)) t.remove_prefix(2);
  HexBytes parsed = dnbridge::parse_hex_bytes(t, " :-,");
  switch (parsed.error) {
    case HexBytes::Error::kNone:
      return std::move(parsed.bytes);
    case HexBytes::Error::kOneDigit:
      return Parsed<std::vector<std::uint8_t>>::failure(
          fmt::format("hex bytes \"{}\": every byte needs two hex digits", text));
    case HexBytes::Error::kNotHexDigit:
      break;
  }
  return Parsed<std::vector<std::uint8_t>>::failure(
      fmt::format("hex bytes \"{}\": '{}' is not a hex digit", text, parsed.bad));
}

std::string hex_bytes(std::span<const std::uint8_t> data) {
  std::string out;
  out.reserve(data.size() * 3);
  for (std::size_t i = 0; i < data.size(); ++i) {
    if (i != 0) out += ' ';
    out += fmt::format("{:02X}", data[i]);
  }
  return out;
}

Parsed<Decoding> parse_decoding(std::string_view text) {
  const std::string t = to_lower(trim(text));
  if (t == "string") return Decoding::kString;
  if (t == "uint") return Decoding::kUint;
  if (t == "int") return Decoding::kInt;
  return Parsed<Decoding>::failure(fmt::format("--as \"{}\": give string, uint or int", text));
}

Parsed<std::string> decode_data(std::span<const std::uint8_t> data, Decoding as) {
  switch (as) {
    case Decoding::kNone:
      return std::string{};
    case Decoding::kString: {
      auto s = cip::decode_short_string(data);
      if (!s) {
        return Parsed<std::string>::failure(fmt::format(
            "{} byte(s) are not a SHORT_STRING (a length byte, then that many characters)",
            data.size()));
      }
      return cip::utf8_from_iso8859_1(*s);
    }
    case Decoding::kUint:
    case Decoding::kInt: {
      const std::size_t n = data.size();
      if (n != 1 && n != 2 && n != 4 && n != 8) {
        return Parsed<std::string>::failure(
            fmt::format("{} byte(s) are not an integer of 1, 2, 4 or 8 bytes", n));
      }
      std::uint64_t v = little_endian(data);
      if (as == Decoding::kUint) return fmt::format("{}", v);
      // Sign-extend from the integer's own width.
      const unsigned bits = static_cast<unsigned>(n * 8);
      if (bits < 64 && ((v >> (bits - 1)) & 1U) != 0) v |= ~((std::uint64_t{1} << bits) - 1);
      return fmt::format("{}", static_cast<std::int64_t>(v));
    }
  }
  return std::string{};
}

}  // namespace dnbridge::dnbctl
