#include "bridge/devicenet/master/poll_connection.hpp"

#include <algorithm>

#include "bridge/can/can_frame.hpp"
#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {

PollConnection::PollConnection(const NodeConfig& config, const ScannerConfig& port,
                               can::FrameSink& sink, NodeCounters& counters, Listener& listener)
    : config_(config),
      port_(port),
      sink_(sink),
      counters_(counters),
      listener_(listener),
      epr_(config.expected_packet_rate) {}

// --- slots ---------------------------------------------------------------------

TimePoint PollConnection::slot_after(TimePoint after) const {
  // Slots at phase_ + k * period: nodes with the same period but different
  // phases never poll in the same instant.
  const Duration period = config_.poll_period;
  if (after <= phase_) return phase_;
  const auto k = (after - phase_ + period - Duration(1)) / period;
  return phase_ + k * period;
}

void PollConnection::start(TimePoint now) {
  strays_ = 0;
  outstanding_ = false;
  unanswered_ = false;
  consecutive_errors_ = 0;
  last_response_ = now;
  next_slot_ = slot_after(now);
  reassembler_.reset();
}

void PollConnection::stop() {
  next_slot_ = kNever;
  deferred_ = kNever;
  response_deadline_ = kNever;
  outstanding_ = false;
}

void PollConnection::serve_ahead(TimePoint now) {
  // A poll still unanswered leaves the slot to on_timer(), which gives that
  // poll up at its deadline and then serves the slot on time.
  if (next_slot_ == kNever || now >= next_slot_ || outstanding_) return;
  next_slot_ = slot_after(next_slot_ + Duration(1));
  send(now);
}

void PollConnection::on_timer(TimePoint now) {
  if (now >= next_slot_) {
    next_slot_ = slot_after(now + Duration(1));
    if (!outstanding_) send(now);
  }
  if (now >= deferred_) {
    // The end of the minimum gap after the last poll for changed outputs. A
    // poll outstanding now (none should be: any poll sent clears this) leaves
    // the changes to its response, as without the gap.
    deferred_ = kNever;
    if (dirty_ && !outstanding_) send_for_change(now);  // the gap is over: now
  }
}

TimePoint PollConnection::timers_deadline() const {
  return std::min({next_slot_, deferred_, last_response_ + 4 * epr_});
}

// --- outputs -------------------------------------------------------------------

bool PollConnection::set_outputs(Bytes data) {
  const bool changed = idle_ || !std::equal(data.begin(), data.end(), outputs_.view().begin(),
                                            outputs_.view().end());
  outputs_.assign(data);
  idle_ = false;
  if (changed) dirty_ = true;
  return changed;
}

bool PollConnection::set_idle(bool idle) {
  if (idle == idle_) return false;
  idle_ = idle;
  dirty_ = true;
  return true;
}

void PollConnection::force_idle() {
  idle_ = true;
  dirty_ = true;
}

// --- polls ---------------------------------------------------------------------

void PollConnection::send(TimePoint now) {
  const std::uint32_t id = group2_id(config_.mac, Group2Message::kMasterIoPoll);
  const std::size_t size = config_.profile.consumed_size;
  // A zero-length poll is the idle signal; a connection that consumes nothing
  // has no idle condition and always polls empty.
  const bool idle = idle_ || size == 0;
  if (unanswered_) ++counters_.retries;
  ++counters_.polls;
  if (idle) ++counters_.idle_polls;
  if (idle || size <= can::kMaxDataLength) {
    can::CanFrame frame;
    frame.id = id;
    frame.len = static_cast<std::uint8_t>(idle ? 0 : size);
    std::copy_n(outputs_.view().begin(), frame.len, frame.data.begin());
    sink_.send(frame, now);
  } else {
    for (std::size_t i = 0; i < io_fragment_count(size); ++i) {
      can::CanFrame frame;
      frame.id = id;
      auto len = io_fragment(outputs_.view(), i, MutableBytes(frame.data));
      if (!len) break;
      frame.len = static_cast<std::uint8_t>(*len);
      sink_.send(frame, now);
    }
  }
  sent_idle_ = idle;
  sent_outputs_ = outputs_;
  dirty_ = false;
  deferred_ = kNever;  // whatever poll goes out carries the latest outputs
  outstanding_ = true;
  response_deadline_ =
      now + std::min(config_.poll_response_timeout.value_or(port_.poll_response_timeout),
                     config_.poll_period);
}

void PollConnection::send_for_change(TimePoint now) {
  // A command flood would otherwise poll the node as fast as the bus allows
  // and take the bus from every other node; a change that comes alone still
  // goes out at once.
  const TimePoint earliest = last_change_poll_ + config_.immediate_poll_min_gap;
  if (now >= earliest) {
    last_change_poll_ = now;
    send(now);
    return;
  }
  // One poll at the end of the gap carries every change made meanwhile; the
  // node's slot, if it comes first, carries them instead (send() clears
  // deferred_), so no change waits longer than it did without the gap.
  deferred_ = earliest;
}

void PollConnection::send_idle_before_release(TimePoint now) {
  // Frames written to the port leave in the order written: the Release
  // that follows reaches the device after this poll.
  strays_ = outstanding_ ? 2 : 1;
  const bool idle = idle_;
  idle_ = true;
  send(now);
  idle_ = idle;
  // Its answer is a stray, counted above: no poll of the node's own waits.
  outstanding_ = false;
  response_deadline_ = kNever;
}

void PollConnection::give_up() {
  outstanding_ = false;
  unanswered_ = true;
  response_deadline_ = kNever;
}

void PollConnection::drop_outstanding() {
  outstanding_ = false;
  response_deadline_ = kNever;
}

// --- responses -----------------------------------------------------------------

void PollConnection::on_response(Bytes payload, TimePoint now) {
  const std::size_t size = config_.profile.produced_size;
  const auto answered = [&](Bytes inputs) {
    const bool late = !outstanding_;
    outstanding_ = false;
    unanswered_ = false;
    response_deadline_ = kNever;
    consecutive_errors_ = 0;
    last_response_ = now;
    ++counters_.responses;
    applied_idle_ = sent_idle_;
    applied_outputs_ = sent_outputs_;
    listener_.on_poll_answer(inputs, late, now);
  };
  if (payload.empty() && sent_idle_ && size != 0) {
    // An idle poll may be answered with no data as well as with the full
    // response (the manual leaves it open): a valid answer that keeps the
    // connection alive, and carries no inputs.
    ++counters_.idle_empty_responses;
    answered(payload);
    return;
  }
  const IoFrame f = take_io_frame(reassembler_, payload, size);
  if (f.outcome == IoFrame::kComplete) {
    answered(f.message);
  } else if (f.outcome != IoFrame::kIncomplete) {
    listener_.on_bad_poll_answer(f.outcome == IoFrame::kWrongSize ? NodeError::Kind::kPollLength
                                                                  : NodeError::Kind::kPollMalformed,
                                 f.got, now);
  }
  if (f.outcome == IoFrame::kComplete || f.outcome == IoFrame::kWrongSize) reassembler_.reset();
}

void PollConnection::take_stray(Bytes payload) {
  // One message each, whatever its frames.
  const bool fragmented = config_.profile.produced_size > can::kMaxDataLength;
  const FragmentType type =
      payload.empty() ? FragmentType::kLast : decode_fragment_byte(payload[0]).type;
  if (strays_ > 0 &&
      (!fragmented || (type != FragmentType::kFirst && type != FragmentType::kMiddle))) {
    --strays_;
  }
}

}  // namespace dnbridge::devicenet
