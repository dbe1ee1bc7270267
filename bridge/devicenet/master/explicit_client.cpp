#include "bridge/devicenet/master/explicit_client.hpp"

#include <algorithm>

#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {

ExplicitClient::ExplicitClient(MacId master, MacId slave, Config config, can::FrameSink& sink,
                               Listener& listener) noexcept
    : master_(master),
      slave_(slave),
      config_(config),
      sink_(sink),
      listener_(listener),
      sender_(config.fragments) {}

std::uint32_t ExplicitClient::request_id(bool unconnected) const noexcept {
  return group2_id(slave_, unconnected ? Group2Message::kUnconnectedExplicitRequest
                                       : Group2Message::kMasterExplicitRequest);
}

Status ExplicitClient::submit(Tag tag, const RequestMessage& request, bool unconnected,
                              TimePoint now, std::optional<Duration> timeout) noexcept {
  if (cancelling_) return Errc::kStopped;
  if (count_ == kQueueCapacity) return Errc::kBusy;
  Pending& slot = queue_[(head_ + count_) % kQueueCapacity];
  // Allocate and Release address class 3 instance 1 and always use 8/8: the
  // body format is only known from the Allocate response.
  const BodyFormat format = unconnected ? BodyFormat::k8_8 : format_;
  auto size = encode_request(request, format, slot.message.storage());
  // A message longer than the buffer is a request out of range, as documented,
  // not the encoder's kBufferTooSmall (the buffer is not the caller's).
  if (!size) return size.error() == Errc::kBufferTooSmall ? Errc::kOutOfRange : size.error();
  slot.message.resize(*size);
  slot.tag = tag;
  slot.unconnected = unconnected;
  slot.service = request.service;
  slot.timeout = timeout.value_or(config_.response_timeout);
  ++count_;
  if (!outstanding_ && !in_callback_) start_next(now);
  return {};
}

void ExplicitClient::start_next(TimePoint now) noexcept {
  if (outstanding_ || count_ == 0) return;
  current_ = queue_[head_];
  head_ = (head_ + 1) % kQueueCapacity;
  --count_;
  outstanding_ = true;
  // A new transaction toggles XID so that a late answer to the previous one
  // cannot be taken for this one's.
  xid_ = !xid_;
  reassembler_.reset();
  ++counters_.requests;
  send_message(now);
}

void ExplicitClient::send_message(TimePoint now) noexcept {
  const ExplicitHeader header{false, xid_, master_};
  const Bytes message = current_.message.view();
  if (message.size() <= kMaxUnfragmentedMessage) {
    std::array<std::uint8_t, 8> buf{};
    buf[0] = encode_header(header);
    std::copy(message.begin(), message.end(), buf.begin() + 1);
    send_payload(request_id(current_.unconnected), Bytes(buf.data(), message.size() + 1), now);
    response_deadline_ = now + current_.timeout;
    return;
  }
  // Longer requests go in acknowledged fragments; the response timer starts
  // when the last fragment is acknowledged.
  response_deadline_ = kNever;
  if (auto started = sender_.start(header, message, now); !started) {
    fail(Errc::kOutOfRange, now);
    return;
  }
  send_payload(request_id(current_.unconnected), sender_.frame(), now);
}

void ExplicitClient::send_payload(std::uint32_t can_id, Bytes payload, TimePoint now) noexcept {
  auto frame = can::CanFrame::make(can_id, payload);
  if (frame) sink_.send(*frame, now);
}

void ExplicitClient::on_frame(Bytes payload, TimePoint now) noexcept {
  if (payload.empty()) {
    ++counters_.malformed_frames;
    return;
  }
  const ExplicitHeader header = decode_header(payload[0]);
  // On Group 2 the header carries the master's MAC: an answer with another
  // MAC belongs to another master's conversation with this slave.
  if (header.mac != master_) {
    ++counters_.unexpected_frames;
    return;
  }
  if ((!outstanding_ || header.xid != xid_) && reack_final_fragment(payload, now)) return;
  if (!outstanding_) {
    ++counters_.unexpected_frames;
    return;
  }
  if (!header.frag) {
    if (header.xid != xid_) {
      ++counters_.unexpected_frames;
      return;
    }
    end_request_transfer(now);
    handle_response(payload.subspan(1), now);
    return;
  }
  if (payload.size() < 2) {
    ++counters_.malformed_frames;
    return;
  }
  const FragmentByte fragment = decode_fragment_byte(payload[1]);
  if (fragment.type == FragmentType::kAck) {
    if (!sender_.active()) {
      ++counters_.unexpected_frames;
      return;
    }
    switch (sender_.on_ack(payload, now)) {
      case ExplicitFragmentSender::Step::kSend:
        send_payload(request_id(current_.unconnected), sender_.frame(), now);
        break;
      case ExplicitFragmentSender::Step::kComplete:
        response_deadline_ = now + current_.timeout;
        break;
      case ExplicitFragmentSender::Step::kFailed:
        // A negative ack: the device refused a fragment (error / too much
        // data). No CIP status came with it, so it is an aborted transfer,
        // not a device error reply.
        ++counters_.fragment_aborts;
        fail(Errc::kAborted, now);
        break;
      case ExplicitFragmentSender::Step::kNone:
        ++counters_.unexpected_frames;
        break;
    }
    return;
  }
  // A fragment of the response.
  if (header.xid != xid_) {
    ++counters_.unexpected_frames;
    return;
  }
  end_request_transfer(now);
  const auto outcome = reassembler_.on_fragment(payload);
  // The reassembler says which fragments are acknowledged (an empty ack()
  // means none); acks go back on the explicit connection.
  if (!reassembler_.ack().empty()) send_payload(request_id(false), reassembler_.ack(), now);
  switch (outcome) {
    case ExplicitReassembler::Outcome::kAccepted:
    case ExplicitReassembler::Outcome::kRepeated:
      // The response is arriving: its next fragment may take the slave's own
      // ack timeout and a resend, so the wait starts again from here.
      response_deadline_ = now + current_.timeout;
      break;
    case ExplicitReassembler::Outcome::kComplete: {
      final_fragment_ = {payload[0], payload[1]};
      final_ack_.assign(reassembler_.ack());
      // Copy out: handling the response may start the next transaction,
      // which resets the reassembler.
      InlineBytes<kMaxExplicitMessage> message;
      message.assign(reassembler_.message());
      handle_response(message.view(), now);
      break;
    }
    case ExplicitReassembler::Outcome::kOverflow:
      ++counters_.malformed_frames;
      fail(Errc::kOutOfRange, now);
      break;
    case ExplicitReassembler::Outcome::kRestarted:
      ++counters_.malformed_frames;
      if (reassembler_.in_progress()) response_deadline_ = now + current_.timeout;
      break;
    case ExplicitReassembler::Outcome::kDropped:
      ++counters_.malformed_frames;
      break;
  }
}

// A response that comes before the request's transfer is done (without the
// acknowledge of its last fragment, or before its other fragments went out)
// ends the transfer: some devices never acknowledge the last fragment and
// send the response instead, and a device that answers early wants no more.
// Counted, as it departs from the acknowledged fragmentation protocol. The
// response timer runs from here: a frame that turns out not to be the answer
// (another service, a fragment out of order) leaves the request to time out
// rather than wait for ever.
void ExplicitClient::end_request_transfer(TimePoint now) noexcept {
  if (!sender_.active()) return;
  sender_.cancel();
  ++counters_.responses_before_final_ack;
  response_deadline_ = now + current_.timeout;
}

// The slave resends the last fragment of a response when it misses the ack
// (bridge/PROTOCOL.md §5), by then the transaction is over (and the next one may
// be under way with the other XID). Re-ack it, or the slave gives up on a
// response that arrived. Nothing else of an ended transfer is acked.
bool ExplicitClient::reack_final_fragment(Bytes payload, TimePoint now) noexcept {
  if (final_ack_.empty() || payload.size() < 2 || payload[0] != final_fragment_[0] ||
      payload[1] != final_fragment_[1]) {
    return false;
  }
  send_payload(request_id(false), final_ack_.view(), now);
  return true;
}

void ExplicitClient::handle_response(Bytes message, TimePoint now) noexcept {
  auto response = decode_response(message);
  if (!response) {
    ++counters_.malformed_frames;
    fail(Errc::kMalformed, now);
    return;
  }
  if (!response->is_error() && response->service != current_.service) {
    // An answer to some other request: not ours, keep waiting.
    ++counters_.unexpected_frames;
    return;
  }
  ExplicitResult result;
  result.service = current_.service;
  if (response->is_error()) {
    ++counters_.device_errors;
    result.error = make_error_code(Errc::kDeviceError);
    result.general_status = response->general_status;
    result.additional_status = response->additional_status;
  } else {
    ++counters_.responses;
    if (!result.data.assign(response->data)) {
      fail(Errc::kOutOfRange, now);
      return;
    }
  }
  finish(result, now);
}

void ExplicitClient::on_timer(TimePoint now) noexcept {
  if (sender_.active() && now >= sender_.deadline()) {
    switch (sender_.on_timer(now)) {
      case ExplicitFragmentSender::Step::kSend:
        send_payload(request_id(current_.unconnected), sender_.frame(), now);
        break;
      case ExplicitFragmentSender::Step::kFailed:
        ++counters_.fragment_aborts;
        fail(sender_.failure(), now);
        return;
      default:
        break;
    }
  }
  if (outstanding_ && now >= response_deadline_) {
    ++counters_.timeouts;
    fail(Errc::kTimeout, now);
  }
}

TimePoint ExplicitClient::deadline() const noexcept {
  if (!outstanding_) return kNever;
  return std::min(sender_.deadline(), response_deadline_);
}

void ExplicitClient::fail(Errc reason, TimePoint now) noexcept {
  ExplicitResult result;
  result.error = make_error_code(reason);
  result.service = current_.service;
  finish(result, now);
}

void ExplicitClient::finish(const ExplicitResult& result, TimePoint now) noexcept {
  outstanding_ = false;
  response_deadline_ = kNever;
  sender_.cancel();
  reassembler_.reset();
  const bool nested = in_callback_;
  in_callback_ = true;
  listener_.on_explicit_result(current_.tag, result, now);
  in_callback_ = nested;
  if (!in_callback_ && !cancelling_) start_next(now);
}

void ExplicitClient::cancel_all(Errc reason, TimePoint now) noexcept {
  cancelling_ = true;
  if (outstanding_) fail(reason, now);
  while (count_ > 0) {
    current_ = queue_[head_];
    head_ = (head_ + 1) % kQueueCapacity;
    --count_;
    fail(reason, now);
  }
  cancelling_ = false;
}

}  // namespace dnbridge::devicenet
