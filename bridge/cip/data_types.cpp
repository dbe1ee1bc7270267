#include "bridge/cip/data_types.hpp"

namespace dnbridge::cip {
namespace {

std::string_view as_text(Bytes b) noexcept {
  // Bytes are std::uint8_t: viewing them as char is an aliasing-safe cast.
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

Result<std::string_view> whole(ByteReader& r, std::string_view text) noexcept {
  if (!r.ok()) return Errc::kTruncated;
  if (!r.at_end()) return Errc::kMalformed;
  return text;
}

Result<std::size_t> write_text(ByteWriter& w, std::string_view text) noexcept {
  for (char c : text) w.u8(static_cast<std::uint8_t>(c));
  if (!w.ok()) return Errc::kBufferTooSmall;
  return w.size();
}

}  // namespace

std::string_view read_fixed_string(ByteReader& reader, std::size_t length) noexcept {
  const Bytes chars = reader.bytes(length);
  if (!reader.ok()) return {};
  return as_text(chars);
}

std::string_view read_short_string(ByteReader& reader) noexcept {
  const std::uint8_t length = reader.u8();
  return read_fixed_string(reader, length);
}

std::string_view read_string(ByteReader& reader) noexcept {
  const std::uint16_t length = reader.u16le();
  return read_fixed_string(reader, length);
}

Result<std::string_view> decode_short_string(Bytes data) noexcept {
  ByteReader r(data);
  const std::string_view text = read_short_string(r);
  return whole(r, text);
}

Result<std::string_view> decode_string(Bytes data) noexcept {
  ByteReader r(data);
  const std::string_view text = read_string(r);
  return whole(r, text);
}

Result<std::size_t> encode_short_string(std::string_view text, MutableBytes out) noexcept {
  if (text.size() > kMaxShortStringLength) return Errc::kOutOfRange;
  if (out.size() < short_string_size(text)) return Errc::kBufferTooSmall;
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(text.size()));
  return write_text(w, text);
}

Result<std::size_t> encode_string(std::string_view text, MutableBytes out) noexcept {
  if (text.size() > kMaxStringLength) return Errc::kOutOfRange;
  if (out.size() < string_size(text)) return Errc::kBufferTooSmall;
  ByteWriter w(out);
  w.u16le(static_cast<std::uint16_t>(text.size()));
  return write_text(w, text);
}

std::string_view trim_padding(std::string_view text) noexcept {
  while (!text.empty() && (text.back() == '\0' || text.back() == ' ')) text.remove_suffix(1);
  return text;
}

std::string utf8_from_iso8859_1(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x80) {
      out += c;
    } else {
      out += static_cast<char>(0xC0 | (u >> 6));
      out += static_cast<char>(0x80 | (u & 0x3F));
    }
  }
  return out;
}

}  // namespace dnbridge::cip
