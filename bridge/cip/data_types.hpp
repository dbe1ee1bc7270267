#pragma once
// CIP elementary string types as DeviceNet devices send them (no pad bytes).
//   SHORT_STRING: USINT length, then that many 8-bit characters. The CDN127
//                 Identity product name is `06 'C' 'D' 'N' '1' '2' '7'`
//                 (CDN127 manual, "Identity Object Instance Attributes", 7).
//   STRING:       UINT length (little-endian), then that many 8-bit characters.
//   STRING[n]:    n characters whose length the object definition fixes.
// Decoders return views into the input: they are valid as long as the input
// is, and copying them into a std::string is the caller's choice (no codec
// allocates). Characters are passed through as they are (ISO 8859-1 by CIP).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"

namespace dnbridge::cip {

inline constexpr std::size_t kMaxShortStringLength = 0xFF;
inline constexpr std::size_t kMaxStringLength = 0xFFFF;

// Readers for use inside larger structures: on failure the reader is marked
// failed and an empty view returned, so a decoder can read on and check ok()
// once.
std::string_view read_short_string(ByteReader& reader) noexcept;
std::string_view read_string(ByteReader& reader) noexcept;
std::string_view read_fixed_string(ByteReader& reader, std::size_t length) noexcept;

// Whole-input decoders: kTruncated if the characters are cut off, kMalformed if
// bytes follow the string.
Result<std::string_view> decode_short_string(Bytes data) noexcept;
Result<std::string_view> decode_string(Bytes data) noexcept;

// Sizes and encoders: kOutOfRange if the text is longer than the length field
// allows, kBufferTooSmall if `out` cannot hold it. Return the size written.
constexpr std::size_t short_string_size(std::string_view text) noexcept { return 1 + text.size(); }
constexpr std::size_t string_size(std::string_view text) noexcept { return 2 + text.size(); }
Result<std::size_t> encode_short_string(std::string_view text, MutableBytes out) noexcept;
Result<std::size_t> encode_string(std::string_view text, MutableBytes out) noexcept;

// Some devices pad fixed-length names with NULs or spaces ("CDN127  "): the
// text without that trailing padding.
std::string_view trim_padding(std::string_view text) noexcept;

// A device's characters (ISO 8859-1: each byte the code point of its value)
// as UTF-8, the encoding of every string the bridge publishes: "\xB5s" is
// "\xC2\xB5s". Allocates: for publishing, not for the codecs.
std::string utf8_from_iso8859_1(std::string_view text);

}  // namespace dnbridge::cip
