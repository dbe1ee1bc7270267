// Node: the poll connection (scheduling, idle, outputs, responses).
#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "bridge/devicenet/master/node.hpp"
#include "bridge/devicenet/master/node_internal.hpp"
#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {

using namespace node_detail;

TimePoint Node::next_poll() const {
  return state_ == NodeState::kOnline && !shutting_down_ ? poll_.next_slot() : kNever;
}

void Node::poll_ahead(TimePoint now) {
  if (next_poll() != kNever) poll_.serve_ahead(now);
}

void Node::on_poll_response(Bytes payload, TimePoint now) {
  if (state_ != NodeState::kOnline && poll_.strays_expected()) {
    // The answer to the idle poll sent on leaving online (and to a poll
    // outstanding then).
    poll_.take_stray(payload);
    return;
  }
  if (state_ != NodeState::kOnline) {
    // A straggler from before the node went offline, or a device polled by
    // someone else: not ours to take.
    on_bad_poll_answer(NodeError::Kind::kPollUnexpected, static_cast<std::uint32_t>(payload.size()),
                       now);
    return;
  }
  poll_.on_response(payload, now);
}

void Node::continue_shutdown(TimePoint now) {
  if (poll_.dirty()) {
    poll_.send(now);  // the idle poll, after the one that was outstanding
  } else {
    release_for_shutdown(now);
  }
}

void Node::on_poll_answer(Bytes data, bool late, TimePoint now) {
  if (late) {
    // The poll timed out, but the data is the device's and current.
    ++counters_.errors;
    record(NodeError::Kind::kPollUnexpected, now);
  }
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
  if (poll_.dirty() && config_.immediate_poll_on_change) poll_.send_for_change(now);
}

void Node::on_bad_poll_answer(NodeError::Kind kind, std::uint32_t got, TimePoint now) {
  ++counters_.errors;
  record(kind, now, got, static_cast<std::uint32_t>(config_.profile.produced_size));
  error_log_limit_.warn(log_, now, "{}", last_error_.describe());
  if (state_ != NodeState::kOnline) return;
  poll_.drop_outstanding();
  if (shutting_down_) {
    // Answered, if badly: the shutdown goes on as after a good answer.
    continue_shutdown(now);
    return;
  }
  if (const unsigned in_a_row = poll_.count_error(); in_a_row >= port_.max_consecutive_errors) {
    // The poll connection lives (the device answers): idle and released now,
    // not left to the device's watchdog with the outputs last commanded.
    lose_and_release(
        fmt::format("{} bad poll responses in a row: {}", in_a_row, last_error_.describe()), now);
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
  const IoFrame f = take_io_frame(cos_reassembler_, payload, in->produced_size);
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
  if (poll_.set_outputs(data)) poll_for_change(now);
  return {};
}

void Node::set_idle(bool idle, TimePoint now) {
  if (poll_.set_idle(idle)) poll_for_change(now);
}

void Node::poll_for_change(TimePoint now) {
  if (state_ == NodeState::kOnline && config_.immediate_poll_on_change && !poll_.outstanding()) {
    poll_.send_for_change(now);
  }
}

}  // namespace dnbridge::devicenet
