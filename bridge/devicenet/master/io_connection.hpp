#pragma once
// What a node's two I/O connections (poll; change of state, cyclic or
// bit-strobe) share: their allocation as the start-up makes it, and the
// framing of their messages (whole in one frame up to 8 bytes, fragmented
// above).
#include <cstddef>
#include <cstdint>

#include "bridge/common/bytes.hpp"
#include "bridge/devicenet/wire/fragmentation.hpp"

namespace dnbridge::devicenet {

// Largest I/O message handled (fragmented above 8 bytes).
inline constexpr std::size_t kMaxIoMessageSize = 64;

// An I/O connection's allocation, as far as the master knows it.
struct IoAllocation {
  bool allocated = false;  // the device confirmed it
  // Allocate sent: the device may hold the connection with its answer lost,
  // so it is released with the rest until the device refuses it.
  bool requested = false;
  bool release_tried = false;  // its Allocate retried once after a Release

  // Released with the connections the master holds.
  bool held() const { return allocated || requested; }
  void forget() { allocated = requested = false; }
};

// One frame of an I/O message of `size` bytes, taken: whole in it when the
// message fits one frame, else a fragment for `reassembler`. Reset the
// reassembler after a complete message, of the right size or not, once
// `message` (its buffer) is used.
struct IoFrame {
  enum Outcome : std::uint8_t { kIncomplete, kComplete, kWrongSize, kOutOfOrder };
  Outcome outcome = kComplete;
  Bytes message;
  std::uint32_t got = 0;  // the size received (kWrongSize, kOutOfOrder)
};
IoFrame take_io_frame(IoReassembler& reassembler, Bytes payload, std::size_t size);

}  // namespace dnbridge::devicenet
