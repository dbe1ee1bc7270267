// Node: the poll connection (scheduling, idle, outputs, responses).
#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "bridge/devicenet/master/node.hpp"
#include "bridge/devicenet/master/node_internal.hpp"
#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {

using namespace node_detail;

TimePoint Node::next_poll_slot(TimePoint after) const {
  // Slots at poll_phase_ + k * period: nodes with the same period but
  // different phases never poll in the same instant.
  const Duration period = config_.poll_period;
  if (after <= poll_phase_) return poll_phase_;
  const auto k = (after - poll_phase_ + period - Duration(1)) / period;
  return poll_phase_ + k * period;
}

TimePoint Node::next_poll() const {
  return state_ == NodeState::kOnline && !shutting_down_ ? next_poll_ : kNever;
}

void Node::poll_ahead(TimePoint now) {
  // A poll still unanswered leaves the slot to on_timer(), which gives that
  // poll up at its deadline and then serves the slot on time.
  if (next_poll() == kNever || now >= next_poll_ || poll_outstanding_) return;
  next_poll_ = next_poll_slot(next_poll_ + Duration(1));
  send_poll(now);
}

void Node::send_poll(TimePoint now) {
  const std::uint32_t id = group2_id(config_.mac, Group2Message::kMasterIoPoll);
  const std::size_t size = config_.profile.consumed_size;
  // A zero-length poll is the idle signal; a connection that consumes nothing
  // has no idle condition and always polls empty.
  const bool idle = idle_ || size == 0;
  if (poll_unanswered_) ++counters_.retries;
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
  outputs_dirty_ = false;
  deferred_poll_ = kNever;  // whatever poll goes out carries the latest outputs
  poll_outstanding_ = true;
  poll_deadline_ =
      now + std::min(config_.poll_response_timeout.value_or(port_.poll_response_timeout),
                     config_.poll_period);
}

void Node::poll_on_change(TimePoint now) {
  // A command flood would otherwise poll the node as fast as the bus allows
  // and take the bus from every other node; a change that comes alone still
  // goes out at once.
  const TimePoint earliest = last_change_poll_ + config_.immediate_poll_min_gap;
  if (now >= earliest) {
    last_change_poll_ = now;
    send_poll(now);
    return;
  }
  // One poll at the end of the gap carries every change made meanwhile; the
  // node's slot, if it comes first, carries them instead (send_poll clears
  // deferred_poll_), so no change waits longer than it did without the gap.
  deferred_poll_ = earliest;
}

Node::IoFrame Node::io_frame(IoReassembler& reassembler, Bytes payload, std::size_t size) {
  IoFrame f;
  if (size <= can::kMaxDataLength) {
    f.message = payload;
  } else {
    switch (reassembler.on_fragment(payload)) {
      case IoReassembler::Outcome::kIncomplete:
        f.outcome = IoFrame::kIncomplete;
        return f;
      case IoReassembler::Outcome::kComplete:
        f.message = reassembler.message();
        break;
      default:
        f.outcome = IoFrame::kOutOfOrder;
        f.got = static_cast<std::uint32_t>(payload.size());
        return f;
    }
  }
  f.got = static_cast<std::uint32_t>(f.message.size());
  f.outcome = f.message.size() == size ? IoFrame::kComplete : IoFrame::kWrongSize;
  return f;
}

void Node::on_poll_response(Bytes payload, TimePoint now) {
  if (state_ != NodeState::kOnline && stray_poll_responses_ > 0) {
    // The answer to the idle poll sent on leaving online (and to a poll
    // outstanding then): one message each, whatever its frames.
    const bool fragmented = config_.profile.produced_size > can::kMaxDataLength;
    const FragmentType type =
        payload.empty() ? FragmentType::kLast : decode_fragment_byte(payload[0]).type;
    if (!fragmented || (type != FragmentType::kFirst && type != FragmentType::kMiddle)) {
      --stray_poll_responses_;
    }
    return;
  }
  if (state_ != NodeState::kOnline) {
    // A straggler from before the node went offline, or a device polled by
    // someone else: not ours to take.
    bad_poll_response(NodeError::Kind::kPollUnexpected, static_cast<std::uint32_t>(payload.size()),
                      now);
    return;
  }
  const std::size_t size = config_.profile.produced_size;
  if (payload.empty() && sent_idle_ && size != 0) {
    // An idle poll may be answered with no data as well as with the full
    // response (the manual leaves it open): a valid answer that keeps the
    // connection alive, and carries no inputs.
    ++counters_.idle_empty_responses;
    accept_poll_response(payload, now);
    return;
  }
  const IoFrame f = io_frame(io_reassembler_, payload, size);
  if (f.outcome == IoFrame::kComplete) {
    accept_poll_response(f.message, now);
  } else if (f.outcome != IoFrame::kIncomplete) {
    bad_poll_response(f.outcome == IoFrame::kWrongSize ? NodeError::Kind::kPollLength
                                                       : NodeError::Kind::kPollMalformed,
                      f.got, now);
  }
  if (f.outcome == IoFrame::kComplete || f.outcome == IoFrame::kWrongSize) io_reassembler_.reset();
}

void Node::continue_shutdown(TimePoint now) {
  if (outputs_dirty_) {
    send_poll(now);  // the idle poll, after the one that was outstanding
  } else {
    release_for_shutdown(now);
  }
}

void Node::accept_poll_response(Bytes data, TimePoint now) {
  if (!poll_outstanding_) {
    // Late: the poll timed out, but the data is the device's and current.
    ++counters_.errors;
    record(NodeError::Kind::kPollUnexpected, now);
  }
  poll_outstanding_ = false;
  poll_unanswered_ = false;
  poll_deadline_ = kNever;
  consecutive_errors_ = 0;
  last_response_ = now;
  ++counters_.responses;
  applied_idle_ = sent_idle_;
  applied_outputs_ = sent_outputs_;
  // An idle poll answered with no data says nothing of the inputs; where a
  // change-of-state connection produces them, they are its last message's.
  if (data.empty() && cos_ && !cos_->last_data().empty()) {
    data = Bytes(cos_->last_data().data(), cos_->last_data().size());
  }
  if (reports_data_) observer_.on_poll_response(config_.mac, data, now);
  if (shutting_down_) {
    continue_shutdown(now);
    return;
  }
  if (outputs_dirty_ && config_.immediate_poll_on_change) poll_on_change(now);
}

void Node::bad_poll_response(NodeError::Kind kind, std::uint32_t got, TimePoint now) {
  ++counters_.errors;
  record(kind, now, got, static_cast<std::uint32_t>(config_.profile.produced_size));
  error_log_limit_.warn(log_, now, "{}", last_error_.describe());
  if (state_ != NodeState::kOnline) return;
  poll_outstanding_ = false;
  poll_deadline_ = kNever;
  if (shutting_down_) {
    // Answered, if badly: the shutdown goes on as after a good answer.
    continue_shutdown(now);
    return;
  }
  if (++consecutive_errors_ >= port_.max_consecutive_errors) {
    // The poll connection lives (the device answers): idle and released now,
    // not left to the device's watchdog with the outputs last commanded.
    lose_and_release(fmt::format("{} bad poll responses in a row: {}", consecutive_errors_,
                                 last_error_.describe()),
                     now);
  }
}

// --- the input connection: change of state, cyclic or bit-strobe -------------

void Node::on_cos_message(Bytes payload, TimePoint now) { on_input_message(false, payload, now); }

void Node::on_strobe_response(Bytes payload, TimePoint now) {
  on_input_message(true, payload, now);
}

void Node::on_input_message(bool strobe_response, Bytes payload, TimePoint now) {
  const auto& in = config_.profile.input_connection;
  // From the Set of its EPR on (a first message may come before the answer),
  // on the message its kind produces.
  if (!cos_ || in->strobed() != strobe_response ||
      (state_ != NodeState::kOnline && step_ != Step::kCosEpr)) {
    bad_cos_message(
        strobe_response ? NodeError::Kind::kStrobeUnexpected : NodeError::Kind::kCosUnexpected,
        static_cast<std::uint32_t>(payload.size()), now);
    return;
  }
  const IoFrame f = io_frame(cos_reassembler_, payload, in->produced_size);
  if (f.outcome == IoFrame::kComplete) {
    take_cos_message(f.message, now);
  } else if (f.outcome != IoFrame::kIncomplete) {
    // A bit-strobe response is one frame: never out of order.
    bad_cos_message(f.outcome != IoFrame::kWrongSize ? NodeError::Kind::kCosMalformed
                    : strobe_response                ? NodeError::Kind::kStrobeLength
                                                     : NodeError::Kind::kCosLength,
                    f.got, now);
  }
  if (f.outcome == IoFrame::kComplete || f.outcome == IoFrame::kWrongSize) cos_reassembler_.reset();
}

void Node::take_cos_message(Bytes data, TimePoint now) {
  const CosConsumer::Taken taken = cos_->on_message(data, now);
  ++counters_.cos_messages;
  if (taken.repeat) ++counters_.cos_retries;
  if (taken.acknowledge) {
    sink_.send(cos_->ack_frame(), now);
    ++counters_.cos_acks;
  }
  cos_consecutive_errors_ = 0;
  // A retry carries nothing new.
  if (state_ == NodeState::kOnline && reports_data_ && !taken.repeat) {
    observer_.on_poll_response(config_.mac, data, now);
  }
}

void Node::bad_cos_message(NodeError::Kind kind, std::uint32_t got, TimePoint now) {
  // Neither taken nor acknowledged: the device sends it again, or the
  // watchdog ends the connection.
  // A straggler of a connection just released, or a message for another
  // master's connection of a node this one polls, is no news.
  const bool unexpected =
      kind == NodeError::Kind::kCosUnexpected || kind == NodeError::Kind::kStrobeUnexpected;
  if (unexpected &&
      (!config_.profile.input_connection || (!cos_ && state_ != NodeState::kOnline))) {
    ++counters_.cos_errors;
    return;
  }
  ++counters_.cos_errors;
  const auto& in = config_.profile.input_connection;
  const std::size_t expected = in ? in->produced_size : 0;
  record(kind, now, got, static_cast<std::uint32_t>(expected));
  error_log_limit_.warn(log_, now, "{}", last_error_.describe());
  if (state_ != NodeState::kOnline) return;
  if (++cos_consecutive_errors_ >= port_.max_consecutive_errors) {
    lose_and_release(
        fmt::format("{} bad {} messages in a row: {}", cos_consecutive_errors_,
                    to_string(config_.profile.input_connection->kind), last_error_.describe()),
        now);
  }
}

Status Node::set_outputs(Bytes data, TimePoint now) {
  if (data.size() != config_.profile.consumed_size) return Errc::kOutOfRange;
  const bool changed = idle_ || !std::equal(data.begin(), data.end(), outputs_.view().begin(),
                                            outputs_.view().end());
  outputs_.assign(data);
  idle_ = false;
  if (!changed) return {};
  outputs_dirty_ = true;
  if (state_ == NodeState::kOnline && config_.immediate_poll_on_change && !poll_outstanding_) {
    poll_on_change(now);
  }
  return {};
}

void Node::set_idle(bool idle, TimePoint now) {
  if (idle == idle_) return;
  idle_ = idle;
  outputs_dirty_ = true;
  if (state_ == NodeState::kOnline && config_.immediate_poll_on_change && !poll_outstanding_) {
    poll_on_change(now);
  }
}

}  // namespace dnbridge::devicenet
