#include "bridge/devicenet/wire/duplicate_mac.hpp"

#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {
namespace {

constexpr std::uint8_t kResponseBit = 0x80;
constexpr std::uint8_t kPortMask = 0x7F;

}  // namespace

Result<can::CanFrame> encode_duplicate_mac(MacId mac, const DuplicateMacMessage& m) noexcept {
  if (m.physical_port > kPortMask) return Errc::kOutOfRange;
  std::uint8_t payload[kDuplicateMacMessageSize] = {};
  ByteWriter w{MutableBytes(payload)};
  w.u8(static_cast<std::uint8_t>((m.response ? kResponseBit : 0) | m.physical_port));
  w.u16le(m.vendor_id);
  w.u32le(m.serial_number);
  return can::CanFrame::make(group2_id(mac, Group2Message::kDuplicateMacCheck), w.written());
}

Result<DuplicateMacMessage> decode_duplicate_mac(Bytes payload) noexcept {
  ByteReader r(payload);
  DuplicateMacMessage m;
  const std::uint8_t first = r.u8();
  m.response = (first & kResponseBit) != 0;
  m.physical_port = first & kPortMask;
  m.vendor_id = r.u16le();
  m.serial_number = r.u32le();
  if (!r.ok()) return Errc::kTruncated;
  if (!r.at_end()) return Errc::kMalformed;
  return m;
}

DuplicateMacCheck::DuplicateMacCheck(MacId mac, Config config) noexcept
    : mac_(mac), config_(config) {
  // The port is a 7-bit field; a larger configured value cannot be sent.
  config_.physical_port &= kPortMask;
}

can::CanFrame DuplicateMacCheck::message(bool response) const noexcept {
  const DuplicateMacMessage m{.response = response,
                              .physical_port = config_.physical_port,
                              .vendor_id = config_.vendor_id,
                              .serial_number = config_.serial_number};
  // Cannot fail: the port is masked to 7 bits and the identifier is in Group 2.
  return encode_duplicate_mac(mac_, m).value();
}

can::CanFrame DuplicateMacCheck::start(TimePoint now) noexcept {
  state_ = State::kChecking;
  requests_sent_ = 1;
  deadline_ = now + config_.window;
  return message(false);
}

std::optional<can::CanFrame> DuplicateMacCheck::on_timer(TimePoint now) noexcept {
  if (state_ != State::kChecking || now < deadline_) return std::nullopt;
  if (requests_sent_ < 2) {
    // The window runs from when the request goes out, so a late timer does not
    // shorten it.
    ++requests_sent_;
    deadline_ = now + config_.window;
    return message(false);
  }
  state_ = State::kOnline;
  return std::nullopt;
}

std::optional<can::CanFrame> DuplicateMacCheck::on_message(const DuplicateMacMessage& m) noexcept {
  switch (state_) {
    case State::kIdle:
    case State::kDuplicate:
      return std::nullopt;  // not on the bus, or already stopped
    case State::kChecking:
      // Anyone else claiming or defending this MAC during the check [CW, JB].
      state_ = State::kDuplicate;
      return std::nullopt;
    case State::kOnline:
      if (m.response) {
        // Another node answered a check for this MAC: it is online with it too.
        state_ = State::kDuplicate;
        return std::nullopt;
      }
      return message(true);  // defend the MAC
  }
  return std::nullopt;
}

TimePoint DuplicateMacCheck::deadline() const noexcept {
  return state_ == State::kChecking ? deadline_ : kNever;
}

}  // namespace dnbridge::devicenet
