#pragma once
// Filling the generated structs without touching malloc: their strings and
// sequences are heap memory that Cyclone frees with dds_free (through
// dds_sample_free), so they must be allocated with dds_alloc as well.
#include <dds/dds.h>

#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>

#include "dnbridge.h"  // dds_sequence_octet, as idlc generates it

namespace dnbridge::dds {

// Replaces a string member's value.
inline void set_string(char*& field, std::string_view value) {
  char* copy = static_cast<char*>(dds_alloc(value.size() + 1));
  if (!value.empty()) std::memcpy(copy, value.data(), value.size());
  copy[value.size()] = '\0';
  dds_string_free(field);
  field = copy;
}

inline void clear_string(char*& field) noexcept {
  dds_string_free(field);
  field = nullptr;
}

// A string member as a view; a null member reads as empty.
inline std::string_view view(const char* field) noexcept {
  return field == nullptr ? std::string_view{} : std::string_view{field};
}

// sequence<octet> members.
inline void clear_octets(dds_sequence_octet& seq) noexcept {
  if (seq._release) dds_free(seq._buffer);
  seq = dds_sequence_octet{};
}

inline void set_octets(dds_sequence_octet& seq, std::span<const std::uint8_t> value) {
  clear_octets(seq);
  if (value.empty()) return;
  seq._buffer = static_cast<std::uint8_t*>(dds_alloc(value.size()));
  std::memcpy(seq._buffer, value.data(), value.size());
  seq._length = static_cast<std::uint32_t>(value.size());
  seq._maximum = seq._length;
  seq._release = true;
}

inline std::span<const std::uint8_t> view(const dds_sequence_octet& seq) noexcept {
  if (seq._buffer == nullptr) return {};
  return {seq._buffer, seq._length};
}

// Whether the first member of a serialized sample (CDR from its 4-byte
// encapsulation header on), a string, holds a NUL before its end. The
// generated struct's copy of such a string ends at that NUL, so two
// different values would read the same. False for anything that does not
// parse as such.
inline bool leading_string_has_nul(std::span<const unsigned char> cdr) noexcept {
  constexpr std::size_t kHeader = 4;
  if (cdr.size() < kHeader + 4) return false;
  // Encapsulation identifiers: the low bit of the second byte says little endian.
  const bool little = (cdr[1] & 1) != 0;
  std::uint32_t length = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const std::uint32_t byte = cdr[kHeader + (little ? 3 - i : i)];
    length = (length << 8) | byte;
  }
  // The length counts the terminating NUL.
  if (length < 2 || length > cdr.size() - kHeader - 4) return false;
  return std::memchr(cdr.data() + kHeader + 4, 0, length - 1) != nullptr;
}

}  // namespace dnbridge::dds
