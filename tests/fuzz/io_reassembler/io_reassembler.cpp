// Unacknowledged I/O fragmentation. Input: [max size:1][mode:1][rest].
// Mode bit 0 clear: the rest is a sequence of frame payloads [len:1][bytes]
// (len & 0x0F, clipped) fed to an IoReassembler. Mode bit 0 set: the rest is
// a message, split with io_fragment() and reassembled, with the frame that
// mode >> 1 names (if any) repeated.
// Properties: complete messages fit the limit; a message split and fed back
// in order comes out unchanged; every fragment fits a CAN frame.
#include <array>
#include <cstddef>
#include <cstdint>

#include "bridge/devicenet/wire/fragmentation.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::devicenet;

namespace {

using Outcome = IoReassembler::Outcome;

void feed_fragments(std::size_t max_size, ByteReader& in) {
  IoReassembler r(max_size);
  while (in.remaining() > 0) {
    const std::size_t want = in.u8() & 0x0FU;
    const Bytes fragment = in.bytes(want < in.remaining() ? want : in.remaining());
    const Outcome o = r.on_fragment(fragment);
    if (fragment.empty() || fragment.size() > 8) FUZZ_CHECK(o == Outcome::kMalformed);
    if (o == Outcome::kComplete) FUZZ_CHECK(r.message().size() <= max_size);
    FUZZ_CHECK(r.message().size() <= kMaxExplicitMessage);
  }
}

void split_and_join(std::size_t max_size, std::uint8_t mode, Bytes message) {
  const std::size_t frames = io_fragment_count(message.size());
  FUZZ_CHECK((frames == 0) == message.empty());
  IoReassembler r(max_size);
  std::array<std::uint8_t, 8> buf{};
  Outcome last = Outcome::kIncomplete;
  const std::size_t repeat = static_cast<std::size_t>(mode >> 1);
  bool lost = false;  // overflowed, or a middle fragment repeated
  for (std::size_t i = 0; i < frames; ++i) {
    auto n = io_fragment(message, i, MutableBytes(buf));
    FUZZ_CHECK(n.ok());
    FUZZ_CHECK(*n >= 1 && *n <= 8);
    last = r.on_fragment(Bytes(buf.data(), *n));
    if (last == Outcome::kOverflow) lost = true;
    if (i + 1 < frames && !lost) FUZZ_CHECK(last == Outcome::kIncomplete);
    if (i == repeat && i + 1 < frames && !lost) {
      const Outcome again = r.on_fragment(Bytes(buf.data(), *n));
      if (i == 0) {
        // A first fragment always starts the message again; the one in
        // progress is reported discarded.
        FUZZ_CHECK(again == Outcome::kOutOfOrder);
      } else {
        // The same middle fragment again is out of sequence: the message is lost.
        FUZZ_CHECK(again == Outcome::kOutOfOrder);
        lost = true;
      }
    }
  }
  FUZZ_CHECK(!io_fragment(message, frames, MutableBytes(buf)).ok());
  if (frames == 0) return;
  if (lost || message.size() > max_size) {
    FUZZ_CHECK(last != Outcome::kComplete);
    return;
  }
  FUZZ_CHECK(last == Outcome::kComplete);
  FUZZ_CHECK(r.message().size() == message.size());
  for (std::size_t i = 0; i < message.size(); ++i) FUZZ_CHECK(r.message()[i] == message[i]);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const std::size_t max_size = data[0] == 0 ? kMaxExplicitMessage : data[0];
  const std::uint8_t mode = data[1];
  ByteReader in(Bytes(data + 2, size - 2));
  if ((mode & 1U) == 0) {
    feed_fragments(max_size, in);
  } else {
    split_and_join(max_size, mode, in.rest());
  }
  return 0;
}
