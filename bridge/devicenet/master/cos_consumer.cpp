#include "bridge/devicenet/master/cos_consumer.hpp"

#include <algorithm>

#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {

CosConsumer::CosConsumer(MacId slave, CosSettings settings, TimePoint established)
    : slave_(slave), settings_(settings), last_(established), original_(established) {}

CosConsumer::Taken CosConsumer::on_message(Bytes data, TimePoint now) {
  Taken taken;
  const bool same = have_data_ && std::equal(data.begin(), data.end(), data_.begin(), data_.end());
  // Retry k comes k acknowledge timers after the message it repeats; a
  // heartbeat or cycle an EPR after it. Either may come a little early.
  const Duration since = now - original_;
  const Duration retry_due = (repeats_in_a_row_ + 1) * settings_.ack_timer;
  const bool as_retry = since <= retry_due + settings_.ack_slack;
  const bool before_heartbeat = settings_.expected_packet_rate <= Duration::zero() ||
                                since + settings_.ack_slack < settings_.expected_packet_rate;
  taken.repeat = same && as_retry && before_heartbeat && !settings_.ack_suppressed &&
                 repeats_in_a_row_ < settings_.retry_limit;
  repeats_in_a_row_ = taken.repeat ? static_cast<std::uint8_t>(repeats_in_a_row_ + 1) : 0;
  ++counters_.messages;
  if (taken.repeat) ++counters_.repeats;
  if (!settings_.ack_suppressed) {
    taken.acknowledge = true;
    ++counters_.acks_sent;
  }
  data_.assign(data.begin(), data.end());
  have_data_ = true;
  last_ = now;
  if (!taken.repeat) original_ = now;
  lost_ = false;
  return taken;
}

bool CosConsumer::check_watchdog(TimePoint now) {
  if (lost_ || now < watchdog_deadline()) return false;
  lost_ = true;
  ++counters_.losses;
  return true;
}

can::CanFrame CosConsumer::ack_frame() const noexcept {
  can::CanFrame f;
  f.id = group2_id(slave_, Group2Message::kMasterCosCyclicAck);
  f.len = 0;
  return f;
}

}  // namespace dnbridge::devicenet
