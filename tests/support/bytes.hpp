#pragma once
// Test helpers for writing golden byte vectors.
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "bridge/can/can_frame.hpp"

namespace dnbridge::test {

using ByteVec = std::vector<std::uint8_t>;

inline can::CanFrame frame(std::uint32_t id, std::initializer_list<std::uint8_t> data) {
  return can::CanFrame::make(id, data).value();
}

inline std::string hex(Bytes b) {
  static const char* digits = "0123456789ABCDEF";
  std::string s;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (i) s += ' ';
    s += digits[b[i] >> 4];
    s += digits[b[i] & 0xF];
  }
  return s;
}

inline std::string hex(const can::CanFrame& f) {
  static const char* digits = "0123456789ABCDEF";
  std::string s;
  s += digits[(f.id >> 8) & 0xF];
  s += digits[(f.id >> 4) & 0xF];
  s += digits[f.id & 0xF];
  s += ':';
  if (f.len) s += ' ' + hex(f.payload());
  return s;
}

}  // namespace dnbridge::test
