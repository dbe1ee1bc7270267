#pragma once
// Bounds-checked cursors over wire bytes. Bytes are std::uint8_t rather than
// std::byte: wire codecs do arithmetic on nearly every byte, and casts would
// bury it.
//
// A ByteReader never reads past its end: a read that does not fit returns 0,
// marks the reader failed and leaves the position where it was, so a decoder
// can read a whole structure and check ok() once.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace dnbridge {

using Bytes = std::span<const std::uint8_t>;
using MutableBytes = std::span<std::uint8_t>;

class ByteReader {
 public:
  explicit ByteReader(Bytes data) noexcept : data_(data) {}

  std::uint8_t u8() noexcept {
    if (!take(1)) return 0;
    return data_[pos_ - 1];
  }
  std::uint16_t u16le() noexcept {
    if (!take(2)) return 0;
    return static_cast<std::uint16_t>(data_[pos_ - 2] | (data_[pos_ - 1] << 8));
  }
  std::uint32_t u32le() noexcept {
    if (!take(4)) return 0;
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | data_[pos_ - 4 + static_cast<std::size_t>(i)];
    return v;
  }
  // The next n bytes, or an empty span (and failed) if fewer remain.
  Bytes bytes(std::size_t n) noexcept {
    if (!take(n)) return {};
    return data_.subspan(pos_ - n, n);
  }
  Bytes rest() noexcept { return bytes(remaining()); }
  bool skip(std::size_t n) noexcept { return take(n); }

  bool ok() const noexcept { return !failed_; }
  bool at_end() const noexcept { return pos_ == data_.size(); }
  std::size_t consumed() const noexcept { return pos_; }
  std::size_t remaining() const noexcept { return data_.size() - pos_; }

 private:
  bool take(std::size_t n) noexcept {
    if (failed_ || n > data_.size() - pos_) {
      failed_ = true;
      return false;
    }
    pos_ += n;
    return true;
  }

  Bytes data_;
  std::size_t pos_ = 0;
  bool failed_ = false;
};

// The unsigned integer of up to 8 little-endian bytes (CIP's order); bytes
// beyond the eighth are ignored.
inline std::uint64_t little_endian(Bytes b) noexcept {
  std::uint64_t v = 0;
  for (std::size_t i = b.size() < 8 ? b.size() : 8; i-- > 0;) v = (v << 8) | b[i];
  return v;
}

// Writes into a caller-provided span; a write that does not fit marks the writer
// failed and writes nothing.
class ByteWriter {
 public:
  explicit ByteWriter(MutableBytes out) noexcept : out_(out) {}

  void u8(std::uint8_t v) noexcept {
    if (room(1)) out_[pos_++] = v;
  }
  void u16le(std::uint16_t v) noexcept {
    if (!room(2)) return;
    out_[pos_++] = static_cast<std::uint8_t>(v & 0xFF);
    out_[pos_++] = static_cast<std::uint8_t>(v >> 8);
  }
  void u32le(std::uint32_t v) noexcept {
    if (!room(4)) return;
    for (int i = 0; i < 4; ++i) out_[pos_++] = static_cast<std::uint8_t>(v >> (8 * i));
  }
  void bytes(Bytes b) noexcept {
    if (!room(b.size())) return;
    for (std::uint8_t v : b) out_[pos_++] = v;
  }

  bool ok() const noexcept { return !failed_; }
  std::size_t size() const noexcept { return pos_; }
  Bytes written() const noexcept { return Bytes(out_.data(), pos_); }

 private:
  bool room(std::size_t n) noexcept {
    if (failed_ || n > out_.size() - pos_) {
      failed_ = true;
      return false;
    }
    return true;
  }

  MutableBytes out_;
  std::size_t pos_ = 0;
  bool failed_ = false;
};

// A small inline byte buffer with a length: no heap, for messages of bounded size.
template <std::size_t N>
class InlineBytes {
 public:
  InlineBytes() noexcept = default;
  static constexpr std::size_t capacity() noexcept { return N; }
  bool assign(Bytes b) noexcept {
    if (b.size() > N) return false;
    for (std::size_t i = 0; i < b.size(); ++i) data_[i] = b[i];
    size_ = b.size();
    return true;
  }
  bool append(Bytes b) noexcept {
    if (b.size() > N - size_) return false;
    for (std::size_t i = 0; i < b.size(); ++i) data_[size_ + i] = b[i];
    size_ += b.size();
    return true;
  }
  void clear() noexcept { size_ = 0; }
  void resize(std::size_t n) noexcept { size_ = n <= N ? n : N; }
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  Bytes view() const noexcept { return Bytes(data_.data(), size_); }
  MutableBytes storage() noexcept { return MutableBytes(data_.data(), N); }
  std::uint8_t operator[](std::size_t i) const noexcept { return data_[i]; }

 private:
  std::array<std::uint8_t, N> data_{};
  std::size_t size_ = 0;
};

}  // namespace dnbridge
