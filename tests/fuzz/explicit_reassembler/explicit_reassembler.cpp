// Acknowledged explicit fragmentation. Input: [max size:1][mode:1][rest].
// Mode bit 0 clear: the rest is a sequence of frame payloads [len:1][bytes]
// (len & 0x0F, clipped to what is left) fed to an ExplicitReassembler.
// Mode bit 0 set: the rest is a message sent by an ExplicitFragmentSender to
// a reassembler, acks lost or corrupted as the mode's other bits say.
// Properties: acks are 0 or 3 bytes and name the fragment's count; a message
// is complete only within the size limit; the sender/reassembler pair
// delivers the message unchanged or fails cleanly, in a bounded number of
// steps.
#include <cstddef>
#include <cstdint>

#include "bridge/devicenet/wire/fragmentation.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::devicenet;

namespace {

using Outcome = ExplicitReassembler::Outcome;

void check_ack(const ExplicitReassembler& r, Outcome o, Bytes fragment) {
  const Bytes ack = r.ack();
  switch (o) {
    case Outcome::kDropped:
      FUZZ_CHECK(ack.empty());
      return;
    case Outcome::kRestarted:
      // Acked only when a first fragment started a new transfer.
      if (!r.in_progress()) FUZZ_CHECK(ack.empty());
      break;
    default:
      FUZZ_CHECK(ack.size() == 3);
      break;
  }
  if (ack.empty()) return;
  FUZZ_CHECK(ack.size() == 3);
  FUZZ_CHECK(fragment.size() >= 2);
  FUZZ_CHECK((ack[0] & 0x80) != 0);  // Frag bit
  const FragmentByte f = decode_fragment_byte(ack[1]);
  FUZZ_CHECK(f.type == FragmentType::kAck);
  FUZZ_CHECK(f.count == decode_fragment_byte(fragment[1]).count);
  FUZZ_CHECK(ack[2] == (o == Outcome::kOverflow ? 1 : 0));
}

void feed_fragments(std::size_t max_size, ByteReader& in) {
  ExplicitReassembler r(max_size);
  while (in.remaining() > 0) {
    const std::size_t want = in.u8() & 0x0FU;
    const Bytes fragment = in.bytes(want < in.remaining() ? want : in.remaining());
    const Outcome o = r.on_fragment(fragment);
    check_ack(r, o, fragment);
    if (o == Outcome::kComplete) {
      FUZZ_CHECK(!r.in_progress());
      // A first and a last fragment without data complete an empty message;
      // its readers (ExplicitClient, the simulated slave) refuse it.
      FUZZ_CHECK(r.message().size() <= max_size);
    }
    if (o == Outcome::kOverflow) FUZZ_CHECK(!r.in_progress());
    FUZZ_CHECK(r.message().size() <= kMaxExplicitMessage);
  }
}

void transfer(std::size_t max_size, std::uint8_t mode, Bytes message) {
  ExplicitFragmentSender sender;
  ExplicitReassembler receiver(max_size);
  TimePoint now = TimePoint{} + seconds(1);
  const ExplicitHeader header{false, (mode & 0x02) != 0, MacId::from_bits(mode >> 2)};
  const Status started = sender.start(header, message, now);
  FUZZ_CHECK(started.ok() == (!message.empty() && message.size() <= kMaxExplicitMessage));
  if (!started) return;
  // Which acks are lost: bit i of the pattern for the i-th ack (cycling).
  const std::uint8_t lost = static_cast<std::uint8_t>(mode >> 3);
  bool complete = false;
  for (unsigned step = 0, acks = 0; sender.active(); ++step) {
    FUZZ_CHECK(step < 4 * (kMaxExplicitMessage / kExplicitFragmentData + 2));
    const Outcome o = receiver.on_fragment(sender.frame());
    if (o == Outcome::kComplete) complete = true;
    const bool drop = lost != 0 && ((lost >> (acks++ % 5)) & 1U) != 0;
    ExplicitFragmentSender::Step s = ExplicitFragmentSender::Step::kNone;
    if (!receiver.ack().empty() && !drop) {
      s = sender.on_ack(receiver.ack(), now);
    } else {
      now = sender.deadline();
      s = sender.on_timer(now);
    }
    if (s == ExplicitFragmentSender::Step::kComplete) {
      FUZZ_CHECK(!sender.active());
      FUZZ_CHECK(complete);
      FUZZ_CHECK(receiver.message().size() == message.size());
      for (std::size_t i = 0; i < message.size(); ++i)
        FUZZ_CHECK(receiver.message()[i] == message[i]);
    }
    if (s == ExplicitFragmentSender::Step::kFailed) FUZZ_CHECK(!sender.active());
  }
  // With no ack lost the message always arrives when it fits the receiver.
  if (lost == 0 && message.size() <= max_size) FUZZ_CHECK(complete);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  // 0 means the default; small limits reach the overflow paths.
  const std::size_t max_size = data[0] == 0 ? kMaxExplicitMessage : data[0];
  const std::uint8_t mode = data[1];
  ByteReader in(Bytes(data + 2, size - 2));
  if ((mode & 1U) == 0) {
    feed_fragments(max_size, in);
  } else {
    transfer(max_size, mode, in.rest());
  }
  return 0;
}
