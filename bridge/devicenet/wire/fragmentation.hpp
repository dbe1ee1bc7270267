#pragma once
// DeviceNet fragmentation (bridge/PROTOCOL.md §5).
//
// Fragment byte: bits 7..6 type (0 first, 1 middle, 2 last, 3 ack), bits 5..0
// count (first = 0, then +1 each, modulo 64).
//
// Explicit messages, acknowledged:
//   fragment: [header with Frag=1][fragment byte][up to 6 message bytes]
//   ack:      [header with Frag=1][0xC0 | count][ack status]   (0 ok, 1 error)
// The receiver acks every fragment, the last included. The sender waits for
// each ack, resends once when it does not come in time, then gives up.
//
// I/O messages over 8 bytes, unacknowledged:
//   [fragment byte][up to 7 message bytes], back to back.
//
// Both classes are sans-IO: they take payloads and the time, and hand back
// payloads to send and deadlines. The caller owns the CAN identifiers.
#include <cstddef>
#include <cstdint>

#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"

namespace dnbridge::devicenet {

enum class FragmentType : std::uint8_t { kFirst = 0, kMiddle = 1, kLast = 2, kAck = 3 };

struct FragmentByte {
  FragmentType type = FragmentType::kFirst;
  std::uint8_t count = 0;  // 0..63

  friend bool operator==(const FragmentByte&, const FragmentByte&) = default;
};

std::uint8_t encode_fragment_byte(FragmentByte f) noexcept;
FragmentByte decode_fragment_byte(std::uint8_t byte) noexcept;

inline constexpr std::size_t kExplicitFragmentData = 6;
inline constexpr std::size_t kIoFragmentData = 7;

enum class AckStatus : std::uint8_t { kSuccess = 0, kError = 1 };

// ---------------------------------------------------------------------------
// Sends one explicit message in acknowledged fragments.
class ExplicitFragmentSender {
 public:
  struct Config {
    Duration ack_timeout = seconds(1);  // spec value UNVERIFIED; implementations use 1 s
    unsigned resends = 1;               // resends of one fragment before giving up
  };

  enum class Step : std::uint8_t {
    kNone,      // nothing to do (frame ignored, or not yet time)
    kSend,      // send frame() now (next fragment, or a resend)
    kComplete,  // the last fragment was acknowledged
    kFailed,    // aborted: see failure()
  };

  ExplicitFragmentSender() noexcept : ExplicitFragmentSender(Config{}) {}
  explicit ExplicitFragmentSender(Config config) noexcept;

  // Starts a transfer of `message` (service byte first, copied). `header` gives
  // XID and MAC; Frag is set by the sender. On success frame() holds the first
  // fragment to send. Fails with kOutOfRange if the message is empty or longer
  // than kMaxExplicitMessage. Starting while a transfer is active replaces it.
  //
  // Fragments carry 6 bytes each, the last one the remaining 1..6 (a message of
  // 6*k bytes ends with a full last fragment). A message that fits in one
  // fragment (1..6 bytes; the caller normally sends up to 7 bytes unfragmented)
  // still goes as a first and a last fragment: the first carries all but the
  // final byte (nothing for a 1-byte message), the last carries that byte.
  Status start(ExplicitHeader header, Bytes message, TimePoint now) noexcept;

  // An ack frame payload [header][0xC0|count][status] from the receiver.
  // An ack for another count, or one that does not parse, is ignored (kNone).
  // A status other than success aborts (kFailed, failure() = kDeviceError).
  // The header's MAC and XID are not checked: the CAN identifier names the
  // connection. Ignored when no transfer is active.
  Step on_ack(Bytes payload, TimePoint now) noexcept;

  // Call when now >= deadline(): resends once (kSend), then fails (kFailed,
  // failure() = kAborted).
  Step on_timer(TimePoint now) noexcept;

  // Abandons the transfer (failure() = kAborted); later acks are ignored.
  void cancel() noexcept;

  bool active() const noexcept { return active_; }
  TimePoint deadline() const noexcept { return active_ ? deadline_ : kNever; }
  Bytes frame() const noexcept { return frame_.view(); }
  Errc failure() const noexcept { return failure_; }

 private:
  void build_frame() noexcept;

  Config config_;
  InlineBytes<kMaxExplicitMessage> message_;
  InlineBytes<8> frame_;
  std::uint8_t header_ = 0;
  std::size_t offset_ = 0;  // start of the fragment in flight
  std::size_t index_ = 0;   // fragment in flight, 0 = first (count_ wraps, this does not)
  std::uint8_t count_ = 0;
  unsigned resends_left_ = 0;
  TimePoint deadline_{};
  bool active_ = false;
  Errc failure_ = Errc::kAborted;
};

// ---------------------------------------------------------------------------
// Reassembles one explicit message from acknowledged fragments, and says
// which ack to send for each: after every outcome, send ack() if it is not
// empty. The rules [JB]:
// - first, count 0: starts a transfer (kAccepted), or restarts the one in
//   progress (kRestarted, in_progress() true, acked). The very same first
//   fragment again while only it has been received is a resend: kRepeated.
// - first, count != 0: kDropped, no ack; a transfer in progress is kept.
// - middle/last with no transfer in progress: kDropped, no ack (the sender
//   times out and gives up). Exception: the last fragment of the message just
//   completed, sent again because its ack was lost, is re-acked (kRepeated).
// - the same fragment byte (type and count) as the previous one: kRepeated,
//   re-acked, nothing appended.
// - next count (previous + 1 modulo 64): appended and acked (kAccepted), or
//   kComplete for a last fragment.
// - any other count: the transfer is discarded, no ack (kRestarted,
//   in_progress() false).
// - more than max_size bytes: kOverflow, ack with status error, discarded.
// Fragments with more than 6 data bytes, without the Frag bit, or acks: kDropped.
class ExplicitReassembler {
 public:
  enum class Outcome : std::uint8_t {
    kDropped,    // not acceptable (first with count != 0, middle/last with no
                 // transfer in progress, unparsable): no ack
    kAccepted,   // appended; send ack()
    kRepeated,   // a repeat of the previous fragment: send ack() again, nothing appended
    kComplete,   // last fragment appended; send ack(), then read message()
    kOverflow,   // the message would exceed the buffer: send ack() (status error); reset
    kRestarted,  // a count out of sequence: the transfer in progress was discarded
                 // (a first fragment with count 0 starts a new one: see in_progress())
  };

  explicit ExplicitReassembler(std::size_t max_size = kMaxExplicitMessage) noexcept;

  // A whole frame payload [header with Frag][fragment byte][data...].
  Outcome on_fragment(Bytes payload) noexcept;

  // The ack for the fragment last handled: [header with Frag][0xC0|count][status].
  Bytes ack() const noexcept { return ack_.view(); }
  // The reassembled message after kComplete (service byte first); it stays
  // until the next first fragment or reset().
  Bytes message() const noexcept { return message_.view(); }
  bool in_progress() const noexcept { return in_progress_; }
  void reset() noexcept;

 private:
  void make_ack(std::uint8_t header, std::uint8_t count, AckStatus status) noexcept;

  std::size_t max_size_;
  InlineBytes<kMaxExplicitMessage> message_;
  InlineBytes<3> ack_;
  std::uint8_t last_fragment_ = 0;  // fragment byte of the last fragment taken
  bool in_progress_ = false;
  bool completed_ = false;  // last_fragment_ completed a message: a repeat is re-acked
};

// ---------------------------------------------------------------------------
// Unacknowledged I/O fragmentation, for connections whose size is over 8.

// Number of frames an I/O message of `size` bytes takes when fragmented: 7
// bytes per frame, at least a first and a last (a message of 1..7 bytes, which
// would normally go unfragmented, is split as all-but-one byte and one byte).
// 0 for an empty message, which is sent unfragmented (the idle signal).
std::size_t io_fragment_count(std::size_t size) noexcept;
// Writes frame `index` of the fragmented message into `out` (8 bytes) and
// returns its length. Fails if index >= io_fragment_count(message.size()).
Result<std::size_t> io_fragment(Bytes message, std::size_t index, MutableBytes out) noexcept;

// A first fragment always starts a new message (one still in progress is
// discarded: kOutOfOrder, the new first kept). A first with count != 0, or a
// middle/last out of sequence or without a first: kOutOfOrder, nothing kept.
class IoReassembler {
 public:
  enum class Outcome : std::uint8_t {
    kIncomplete,  // more fragments expected
    kComplete,    // message() holds the whole message
    kOutOfOrder,  // a fragment out of sequence: the message was discarded
    kOverflow,    // longer than the buffer: discarded
    kMalformed,   // empty payload, over 8 bytes, or an ack type: discarded
  };

  explicit IoReassembler(std::size_t max_size = kMaxExplicitMessage) noexcept;
  Outcome on_fragment(Bytes payload) noexcept;
  Bytes message() const noexcept { return message_.view(); }
  void reset() noexcept;

 private:
  std::size_t max_size_;
  InlineBytes<kMaxExplicitMessage> message_;
  std::uint8_t next_count_ = 0;
  bool in_progress_ = false;
};

}  // namespace dnbridge::devicenet
