#include "bridge/devicenet/master/input_link.hpp"

#include <fmt/format.h>

#include "bridge/devicenet/master/node_internal.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"

namespace dnbridge::devicenet {

using node_detail::to_ms;

InputLink::InputLink(const NodeConfig& config, can::FrameSink& sink, NodeCounters& counters,
                     Listener& listener)
    : config_(config), sink_(sink), counters_(counters), listener_(listener) {}

std::uint8_t InputLink::choice() const {
  const InputConnection* in = configured();
  if (!in) return 0;
  switch (in->kind) {
    case InputKind::kBitStrobe:
      return allocation::kBitStrobe;
    case InputKind::kCyclic:
      return static_cast<std::uint8_t>(allocation::kCyclic |
                                       (in->acknowledged ? 0 : allocation::kAckSuppression));
    case InputKind::kChangeOfState:
      break;
  }
  return static_cast<std::uint8_t>(allocation::kChangeOfState |
                                   (in->acknowledged ? 0 : allocation::kAckSuppression));
}

std::uint8_t InputLink::connection_bits() const {
  return static_cast<std::uint8_t>(choice() & ~allocation::kAckSuppression);
}

Duration InputLink::epr_asked() const {
  const InputConnection* in = configured();
  if (!in) return Duration::zero();
  return in->strobed() ? config_.expected_packet_rate : in->expected_packet_rate;
}

void InputLink::begin_attempt() {
  allocation_.release_tried = false;
  ack_handler_unread_ = false;
  path_refusal_.clear();
  asked_ = CosSettings{};
  if (const InputConnection* in = configured()) {
    asked_.expected_packet_rate = epr_asked();
    // Nothing acknowledges a bit-strobe response.
    asked_.ack_suppressed = !in->acknowledged || in->strobed();
  }
}

void InputLink::start_consuming(TimePoint now) {
  consumer_.emplace(config_.mac, asked_, now);
  reassembler_.reset();
}

void InputLink::set_epr(Duration epr) {
  asked_.expected_packet_rate = epr;
  if (consumer_) consumer_->set_expected_packet_rate(epr);
}

std::optional<CosSettings> InputLink::settings() const {
  if (!consumer_) return std::nullopt;
  return consumer_->settings();
}

void InputLink::on_message(Bytes payload, TimePoint now) {
  const InputConnection& in = *configured();
  const IoFrame f = take_io_frame(reassembler_, payload, in.produced_size);
  if (f.outcome == IoFrame::kComplete) {
    const CosConsumer::Taken taken = consumer_->on_message(f.message, now);
    ++counters_.cos_messages;
    if (taken.repeat) ++counters_.cos_retries;
    if (taken.acknowledge) {
      sink_.send(consumer_->ack_frame(), now);
      ++counters_.cos_acks;
    }
    errors_in_a_row_ = 0;
    // A retry carries nothing new.
    if (!taken.repeat) listener_.on_inputs(f.message, now);
  } else if (f.outcome != IoFrame::kIncomplete) {
    // A bit-strobe response is one frame: never out of order.
    listener_.on_bad_inputs(f.outcome != IoFrame::kWrongSize ? NodeError::Kind::kCosMalformed
                            : in.strobed()                   ? NodeError::Kind::kStrobeLength
                                                             : NodeError::Kind::kCosLength,
                            f.got, now);
  }
  if (f.outcome == IoFrame::kComplete || f.outcome == IoFrame::kWrongSize) reassembler_.reset();
}

TimePoint InputLink::watchdog_deadline() const {
  return consumer_ ? consumer_->watchdog_deadline() : kNever;
}

bool InputLink::watchdog_expired(TimePoint now) {
  return consumer_ && now >= consumer_->watchdog_deadline() && consumer_->check_watchdog(now);
}

Bytes InputLink::last_data() const {
  if (!consumer_) return {};
  return Bytes(consumer_->last_data().data(), consumer_->last_data().size());
}

std::string InputLink::describe() const {
  if (!consumer_) return {};
  const CosSettings& c = consumer_->settings();
  const InputKind kind = configured()->kind;
  return fmt::format(
      "; inputs {} (EPR {} ms, {})",
      kind == InputKind::kCyclic          ? "cyclic"
      : kind == InputKind::kChangeOfState ? "on change of state"
                                          : "bit-strobed",
      to_ms(c.expected_packet_rate),
      kind == InputKind::kBitStrobe ? std::string("strobed with the port's other nodes")
      : c.ack_suppressed
          ? std::string("acknowledgment suppressed")
          : fmt::format(
                "acknowledged: the device retries after {} ms, {} time(s){}", to_ms(c.ack_timer),
                unsigned{c.retry_limit},
                ack_handler_unread_ ? " (defaults: its Acknowledge Handler not read)" : ""));
}

}  // namespace dnbridge::devicenet
