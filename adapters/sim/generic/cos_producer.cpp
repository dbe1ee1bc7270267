#include "adapters/sim/generic/cos_producer.hpp"

#include <algorithm>

namespace dnbridge::sim {

CosProducer::CosProducer(CosProduction settings, Bytes data, TimePoint established)
    : settings_(settings), data_(data.begin(), data.end()), last_production_(established) {}

std::vector<std::uint8_t> CosProducer::produce(TimePoint now) {
  last_production_ = now;
  change_pending_ = false;
  ++counters_.produced;
  if (!settings_.ack_suppressed) {
    awaiting_ack_ = true;  // a message still waiting is superseded
    awaiting_ = data_;
    retries_left_ = settings_.retry_limit;
    ack_deadline_ = now + ack_timer();
  }
  return data_;
}

Duration CosProducer::ack_timer() const noexcept {
  return std::max<Duration>(settings_.ack_timer, milliseconds(1));
}

std::optional<TimePoint> CosProducer::next_production() const noexcept {
  if (settings_.expected_packet_rate <= Duration::zero()) return std::nullopt;
  return last_production_ + settings_.expected_packet_rate;
}

std::optional<std::vector<std::uint8_t>> CosProducer::set_data(Bytes data, TimePoint now) {
  if (std::equal(data.begin(), data.end(), data_.begin(), data_.end())) return std::nullopt;
  data_.assign(data.begin(), data.end());
  if (settings_.cyclic) return std::nullopt;  // sent at the next cycle
  if (now < last_production_ + settings_.inhibit) {
    change_pending_ = true;
    return std::nullopt;
  }
  return produce(now);
}

void CosProducer::on_ack() {
  if (!awaiting_ack_) {
    // Nothing waiting: too late for a message given up, or again for one
    // acknowledged. Counted, not taken.
    ++counters_.late_acks;
    return;
  }
  awaiting_ack_ = false;
  ++counters_.acks_received;
}

TimePoint CosProducer::next_deadline() const noexcept {
  TimePoint next = next_production().value_or(kNever);
  if (change_pending_) next = std::min(next, last_production_ + settings_.inhibit);
  if (awaiting_ack_) next = std::min(next, ack_deadline_);
  return next;
}

std::optional<std::vector<std::uint8_t>> CosProducer::on_timer(TimePoint now) {
  if (change_pending_ && now >= last_production_ + settings_.inhibit) return produce(now);
  if (const auto due = next_production(); due && now >= *due) return produce(now);
  if (awaiting_ack_ && now >= ack_deadline_) {
    if (retries_left_ == 0) {
      awaiting_ack_ = false;
      ++counters_.given_up;
      return std::nullopt;
    }
    --retries_left_;
    ++counters_.retries;
    ++counters_.produced;
    ack_deadline_ = now + ack_timer();
    return awaiting_;
  }
  return std::nullopt;
}

}  // namespace dnbridge::sim
