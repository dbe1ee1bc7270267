// Node: its I/O connections' traffic (PollConnection, InputLink): the
// outputs and idle flag handed to the poll connection, and what their
// answers, bad answers and strays lead to.
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
  if (data.empty() && !input_.last_data().empty()) data = input_.last_data();
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
  // From the Set of its EPR on (a first message may come before the answer),
  // on the message its kind produces.
  if (!input_.consuming() || input_.configured()->strobed() != strobe_response ||
      (state_ != NodeState::kOnline && step_ != Step::kCosEpr)) {
    on_bad_inputs(
        strobe_response ? NodeError::Kind::kStrobeUnexpected : NodeError::Kind::kCosUnexpected,
        static_cast<std::uint32_t>(payload.size()), now);
    return;
  }
  input_.on_message(payload, now);
}

void Node::on_inputs(Bytes data, TimePoint now) {
  if (state_ == NodeState::kOnline && reports_data_) {
    observer_.on_poll_response(config_.mac, data, now);
  }
}

void Node::on_bad_inputs(NodeError::Kind kind, std::uint32_t got, TimePoint now) {
  // Neither taken nor acknowledged: the device sends it again, or the
  // watchdog ends the connection.
  // A straggler of a connection just released, or a message for another
  // master's connection of a node this one polls, is no news.
  const bool unexpected =
      kind == NodeError::Kind::kCosUnexpected || kind == NodeError::Kind::kStrobeUnexpected;
  const InputConnection* in = input_.configured();
  ++counters_.cos_errors;
  if (unexpected && (!in || (!input_.consuming() && state_ != NodeState::kOnline))) return;
  record(kind, now, got, static_cast<std::uint32_t>(in ? in->produced_size : 0));
  error_log_limit_.warn(log_, now, "{}", last_error_.describe());
  if (state_ != NodeState::kOnline) return;
  if (const unsigned in_a_row = input_.count_error(); in_a_row >= port_.max_consecutive_errors) {
    lose_and_release(fmt::format("{} bad {} messages in a row: {}", in_a_row, to_string(in->kind),
                                 last_error_.describe()),
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
