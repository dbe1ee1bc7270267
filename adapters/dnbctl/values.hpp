#pragma once
// What a person types on dnbctl's command line, checked: MAC IDs, numbers in
// decimal or 0x hex, on/off, analog values in volts or raw counts, hex byte
// strings; and the decoding of explicit-message data for display. A value
// out of range is refused with a sentence that says the range, never clipped.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace dnbridge::dnbctl {

// A parsed value, or why the text is not one.
template <class T>
class Parsed {
 public:
  Parsed(T value) : value_(std::move(value)) {}  // NOLINT(implicit)
  static Parsed failure(std::string why) {
    Parsed p;
    p.error_ = std::move(why);
    return p;
  }

  bool ok() const noexcept { return value_.has_value(); }
  explicit operator bool() const noexcept { return ok(); }
  const T& operator*() const noexcept { return *value_; }
  const T* operator->() const noexcept { return &*value_; }
  const std::string& error() const noexcept { return error_; }

 private:
  Parsed() = default;
  std::optional<T> value_;
  std::string error_;
};

// An unsigned number, decimal ("14") or hex with 0x ("0x0E"), 0..max.
// `what` names the value in the message ("class", "MAC ID").
Parsed<std::uint64_t> parse_unsigned(std::string_view text, std::uint64_t max,
                                     std::string_view what);

// A DeviceNet MAC ID, 0..63.
Parsed<std::uint8_t> parse_mac(std::string_view text);

// A node as a command names it: its MAC ID (a number, "12", "0x0C") or its
// name in the bridge's configuration ("chamber-1-dry-pump").
struct NodeRef {
  std::optional<std::uint8_t> mac;  // set when given as a number
  std::string name;                 // set otherwise
  // Whether it names the node at `node_mac` called `node_name`.
  bool matches(std::uint8_t node_mac, std::string_view node_name) const {
    return mac ? *mac == node_mac : name == node_name;
  }
  friend bool operator==(const NodeRef&, const NodeRef&) = default;
};
Parsed<NodeRef> parse_node(std::string_view text);

// "on" or "off" (also 1/0, true/false).
Parsed<bool> parse_on_off(std::string_view text);

// An analog output value: volts with a V suffix ("5.0V", "2.5 v", 0..10) or
// a raw count ("2048", "0x800", 0..4095). Volts are converted to the nearest
// of the 4096 steps, as the bridge's profile does: round(V * 4095 / 10).
struct AnalogValue {
  std::uint16_t raw = 0;
  std::optional<double> volts;  // as typed, when given in volts
};
Parsed<AnalogValue> parse_analog(std::string_view text);

// Hex bytes: "0a1b", "0A 1B", "0a:1b", "0x0a1b"; an empty string is no bytes.
Parsed<std::vector<std::uint8_t>> parse_hex_bytes(std::string_view text);

// "06 43 44" (upper case, space separated); empty for no bytes.
std::string hex_bytes(std::span<const std::uint8_t> data);

// How `get` shows the reply data besides its hex.
enum class Decoding { kNone, kString, kUint, kInt };
Parsed<Decoding> parse_decoding(std::string_view text);  // "string", "uint", "int"

// The data decoded: a CIP SHORT_STRING (length byte, then characters), or a
// little-endian integer of 1, 2, 4 or 8 bytes (USINT..ULINT, SINT..LINT).
Parsed<std::string> decode_data(std::span<const std::uint8_t> data, Decoding as);

}  // namespace dnbridge::dnbctl
