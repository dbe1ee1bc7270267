#include "bridge/devicenet/wire/fragmentation.hpp"

#include <algorithm>

namespace dnbridge::devicenet {
namespace {

constexpr std::uint8_t kFragBit = 0x80;
constexpr std::uint8_t kCountMask = 0x3F;
constexpr std::size_t kExplicitFragmentOverhead = 2;  // header + fragment byte

constexpr std::uint8_t next_count(std::uint8_t count) noexcept {
  return static_cast<std::uint8_t>((count + 1) & kCountMask);
}

struct Span {
  std::size_t offset;
  std::size_t length;
};

// Number of fragments of an n-byte message sent in fragments of up to `chunk`
// bytes. A transfer is always a first and a last fragment at least: a message
// that would fit in one fragment goes as a first carrying all but its final
// byte and a last carrying that byte, so any receiver that follows the rules
// reassembles it. A message of exactly k * chunk bytes ends with a full last
// fragment.
constexpr std::size_t fragment_total(std::size_t n, std::size_t chunk) noexcept {
  if (n == 0) return 0;
  if (n <= chunk) return 2;
  return (n + chunk - 1) / chunk;
}

constexpr Span fragment_span(std::size_t n, std::size_t index, std::size_t chunk) noexcept {
  if (n <= chunk) return index == 0 ? Span{0, n - 1} : Span{n - 1, 1};
  const std::size_t offset = index * chunk;
  return {offset, std::min(chunk, n - offset)};
}

constexpr FragmentType fragment_type(std::size_t index, std::size_t total) noexcept {
  if (index == 0) return FragmentType::kFirst;
  return index + 1 == total ? FragmentType::kLast : FragmentType::kMiddle;
}

}  // namespace

std::uint8_t encode_fragment_byte(FragmentByte f) noexcept {
  return static_cast<std::uint8_t>((static_cast<std::uint8_t>(f.type) << 6) |
                                   (f.count & kCountMask));
}

FragmentByte decode_fragment_byte(std::uint8_t byte) noexcept {
  return {static_cast<FragmentType>(byte >> 6), static_cast<std::uint8_t>(byte & kCountMask)};
}

// ---------------------------------------------------------------------------

ExplicitFragmentSender::ExplicitFragmentSender(Config config) noexcept : config_(config) {}

Status ExplicitFragmentSender::start(ExplicitHeader header, Bytes message, TimePoint now) noexcept {
  // An empty message has no service byte: there is nothing to send.
  if (message.empty() || !message_.assign(message)) return Errc::kOutOfRange;
  header.frag = true;
  header_ = encode_header(header);
  index_ = 0;
  count_ = 0;
  resends_left_ = config_.resends;
  deadline_ = now + config_.ack_timeout;
  active_ = true;
  failure_ = Errc::kAborted;
  build_frame();
  return {};
}

void ExplicitFragmentSender::build_frame() noexcept {
  const std::size_t total = fragment_total(message_.size(), kExplicitFragmentData);
  const Span span = fragment_span(message_.size(), index_, kExplicitFragmentData);
  offset_ = span.offset;
  const std::uint8_t head[] = {header_,
                               encode_fragment_byte({fragment_type(index_, total), count_})};
  frame_.assign(Bytes(head));
  frame_.append(message_.view().subspan(span.offset, span.length));
}

ExplicitFragmentSender::Step ExplicitFragmentSender::on_ack(Bytes payload, TimePoint now) noexcept {
  if (!active_) return Step::kNone;
  ByteReader r(payload);
  const std::uint8_t header = r.u8();
  const FragmentByte fragment = decode_fragment_byte(r.u8());
  const std::uint8_t status = r.u8();
  // The CAN identifier names the connection; the header's MAC and XID are not
  // checked here. Bytes after the status are tolerated.
  if (!r.ok() || (header & kFragBit) == 0 || fragment.type != FragmentType::kAck ||
      fragment.count != count_) {
    return Step::kNone;
  }
  if (status != static_cast<std::uint8_t>(AckStatus::kSuccess)) {
    active_ = false;
    failure_ = Errc::kDeviceError;
    return Step::kFailed;
  }
  ++index_;
  if (index_ >= fragment_total(message_.size(), kExplicitFragmentData)) {
    active_ = false;
    return Step::kComplete;
  }
  count_ = next_count(count_);
  resends_left_ = config_.resends;
  deadline_ = now + config_.ack_timeout;
  build_frame();
  return Step::kSend;
}

ExplicitFragmentSender::Step ExplicitFragmentSender::on_timer(TimePoint now) noexcept {
  if (!active_ || now < deadline_) return Step::kNone;
  if (resends_left_ > 0) {
    --resends_left_;
    deadline_ = now + config_.ack_timeout;
    return Step::kSend;  // frame() is unchanged: the same fragment again
  }
  active_ = false;
  failure_ = Errc::kAborted;
  return Step::kFailed;
}

void ExplicitFragmentSender::cancel() noexcept {
  if (active_) failure_ = Errc::kAborted;
  active_ = false;
}

// ---------------------------------------------------------------------------

ExplicitReassembler::ExplicitReassembler(std::size_t max_size) noexcept
    : max_size_(std::min(max_size, kMaxExplicitMessage)) {}

void ExplicitReassembler::reset() noexcept {
  message_.clear();
  ack_.clear();
  in_progress_ = false;
  last_fragment_ = 0;
  completed_ = false;
}

void ExplicitReassembler::make_ack(std::uint8_t header, std::uint8_t count,
                                   AckStatus status) noexcept {
  const std::uint8_t ack[] = {static_cast<std::uint8_t>(header | kFragBit),
                              encode_fragment_byte({FragmentType::kAck, count}),
                              static_cast<std::uint8_t>(status)};
  ack_.assign(Bytes(ack));
}

ExplicitReassembler::Outcome ExplicitReassembler::on_fragment(Bytes payload) noexcept {
  ack_.clear();
  if (payload.size() < kExplicitFragmentOverhead ||
      payload.size() > kExplicitFragmentOverhead + kExplicitFragmentData ||
      (payload[0] & kFragBit) == 0) {
    return Outcome::kDropped;
  }
  const std::uint8_t header = payload[0];
  const std::uint8_t fragment_byte = payload[1];
  const FragmentByte fragment = decode_fragment_byte(fragment_byte);
  const Bytes data = payload.subspan(kExplicitFragmentOverhead);

  switch (fragment.type) {
    case FragmentType::kAck:
      return Outcome::kDropped;  // an ack is the sender's business

    case FragmentType::kFirst: {
      // A first fragment with a count other than 0 is dropped [JB].
      if (fragment.count != 0) return Outcome::kDropped;
      // The sender resends a first fragment whose ack it missed: same bytes,
      // re-acked, nothing appended.
      if (in_progress_ && last_fragment_ == fragment_byte &&
          std::equal(data.begin(), data.end(), message_.view().begin(), message_.view().end())) {
        make_ack(header, fragment.count, AckStatus::kSuccess);
        return Outcome::kRepeated;
      }
      const bool restarted = in_progress_;
      message_.clear();
      completed_ = false;
      if (data.size() > max_size_) {
        in_progress_ = false;
        make_ack(header, fragment.count, AckStatus::kError);
        return Outcome::kOverflow;
      }
      message_.append(data);
      in_progress_ = true;
      last_fragment_ = fragment_byte;
      make_ack(header, fragment.count, AckStatus::kSuccess);
      return restarted ? Outcome::kRestarted : Outcome::kAccepted;
    }

    case FragmentType::kMiddle:
    case FragmentType::kLast:
      break;
  }

  if (!in_progress_) {
    // The final fragment again after completion: its ack was lost. Re-ack it so
    // the sender does not give up on a message that arrived.
    if (completed_ && fragment_byte == last_fragment_) {
      make_ack(header, fragment.count, AckStatus::kSuccess);
      return Outcome::kRepeated;
    }
    // A middle or last fragment with no first: nothing to append to, no ack.
    return Outcome::kDropped;
  }
  if (fragment_byte == last_fragment_) {
    make_ack(header, fragment.count, AckStatus::kSuccess);
    return Outcome::kRepeated;
  }
  if (fragment.count != next_count(decode_fragment_byte(last_fragment_).count)) {
    // A count out of sequence: the transfer is discarded [JB], not acked.
    reset();
    return Outcome::kRestarted;
  }
  if (data.size() > max_size_ - message_.size()) {
    reset();
    make_ack(header, fragment.count, AckStatus::kError);
    return Outcome::kOverflow;
  }
  message_.append(data);
  last_fragment_ = fragment_byte;
  make_ack(header, fragment.count, AckStatus::kSuccess);
  if (fragment.type == FragmentType::kLast) {
    in_progress_ = false;
    completed_ = true;
    return Outcome::kComplete;
  }
  return Outcome::kAccepted;
}

// ---------------------------------------------------------------------------

std::size_t io_fragment_count(std::size_t size) noexcept {
  // An empty I/O message (the idle signal) is sent unfragmented: no fragments.
  return fragment_total(size, kIoFragmentData);
}

Result<std::size_t> io_fragment(Bytes message, std::size_t index, MutableBytes out) noexcept {
  const std::size_t total = io_fragment_count(message.size());
  if (index >= total) return Errc::kOutOfRange;
  const Span span = fragment_span(message.size(), index, kIoFragmentData);
  ByteWriter w(out);
  w.u8(encode_fragment_byte(
      {fragment_type(index, total), static_cast<std::uint8_t>(index & kCountMask)}));
  w.bytes(message.subspan(span.offset, span.length));
  if (!w.ok()) return Errc::kBufferTooSmall;
  return w.size();
}

IoReassembler::IoReassembler(std::size_t max_size) noexcept
    : max_size_(std::min(max_size, kMaxExplicitMessage)) {}

void IoReassembler::reset() noexcept {
  message_.clear();
  next_count_ = 0;
  in_progress_ = false;
}

IoReassembler::Outcome IoReassembler::on_fragment(Bytes payload) noexcept {
  if (payload.empty() || payload.size() > 1 + kIoFragmentData) {
    reset();
    return Outcome::kMalformed;
  }
  const FragmentByte fragment = decode_fragment_byte(payload[0]);
  const Bytes data = payload.subspan(1);
  bool discarded = false;
  switch (fragment.type) {
    case FragmentType::kAck:
      reset();
      return Outcome::kMalformed;  // I/O fragments are not acknowledged
    case FragmentType::kFirst:
      // A first fragment always begins a new message; one still in progress
      // lost its end and is reported discarded (the new first is kept).
      discarded = in_progress_;
      reset();
      if (fragment.count != 0) return Outcome::kOutOfOrder;
      break;
    case FragmentType::kMiddle:
    case FragmentType::kLast:
      if (!in_progress_ || fragment.count != next_count_) {
        reset();
        return Outcome::kOutOfOrder;
      }
      break;
  }
  if (data.size() > max_size_ - message_.size()) {
    reset();
    return Outcome::kOverflow;
  }
  message_.append(data);
  in_progress_ = fragment.type != FragmentType::kLast;
  next_count_ = next_count(fragment.count);
  if (fragment.type == FragmentType::kLast) return Outcome::kComplete;
  return discarded ? Outcome::kOutOfOrder : Outcome::kIncomplete;
}

}  // namespace dnbridge::devicenet
