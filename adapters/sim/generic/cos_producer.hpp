#pragma once
// A simulated slave's end of its change-of-state or cyclic connection
// (instance 4 of the predefined master/slave set), as the Acknowledge
// Handler object describes it (class 0x2B; LUFP9 manual, appendix D,
// shared/seeds/000):
// - change of state: a message when the data changes, no sooner than the
//   production inhibit time after the one before, and the data again once
//   per expected packet rate (EPR) when nothing changed (the heartbeat);
// - cyclic: the data every EPR, changes or not;
// - unless acknowledgment is suppressed, each message waits for the
//   master's acknowledgment; none within the acknowledge timer (attribute
//   1, default 20 ms), the message is sent again, at most the retry limit
//   (attribute 2, default 1) times in a row; then the device gives it up.
//   A new message supersedes one still waiting; a change held back by the
//   inhibit time waits for its own turn, never rides on a retry.
// An EPR of 0 means no heartbeat (nor, cyclic, any production), as the
// Connection object's 0 is read (UNVERIFIED); an acknowledge timer of 0,
// outside the object's 1..65535, is taken as 1 ms.
//
// Sans-IO: time comes in as arguments; what to send comes back, the caller
// puts it on the bus (Group 1 message 0xD).
#include <cstdint>
#include <optional>
#include <vector>

#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::sim {

struct CosProduction {
  Duration expected_packet_rate = milliseconds(1000);
  Duration inhibit = Duration::zero();
  bool cyclic = false;
  bool ack_suppressed = false;
  Duration ack_timer = milliseconds(20);  // the Acknowledge Handler's defaults
  std::uint8_t retry_limit = 1;
};

struct CosProducerCounters {
  std::uint64_t produced = 0;       // messages, retries included
  std::uint64_t retries = 0;        // sent again for want of an acknowledgment
  std::uint64_t acks_received = 0;  // acknowledgments of a waiting message
  std::uint64_t given_up = 0;       // messages still unacknowledged after the retry limit
  std::uint64_t late_acks = 0;      // acknowledgments with no message waiting (after a give-up)

  CosProducerCounters& operator+=(const CosProducerCounters& o) noexcept {
    produced += o.produced;
    retries += o.retries;
    acks_received += o.acks_received;
    given_up += o.given_up;
    late_acks += o.late_acks;
    return *this;
  }
};

class CosProducer {
 public:
  CosProducer(CosProduction settings, Bytes data, TimePoint established);

  // The device's data now; a message to send at once, if it is due.
  std::optional<std::vector<std::uint8_t>> set_data(Bytes data, TimePoint now);
  // The master's acknowledgment (Group 2 message 2).
  void on_ack();
  // The connection's EPR set again while it runs: the next heartbeat (or
  // cycle) is this long after the last message.
  void set_expected_packet_rate(Duration rate) noexcept { settings_.expected_packet_rate = rate; }
  Duration expected_packet_rate() const noexcept { return settings_.expected_packet_rate; }
  // Call when now >= next_deadline(): a message to send, if any is due.
  std::optional<std::vector<std::uint8_t>> on_timer(TimePoint now);
  TimePoint next_deadline() const noexcept;

  bool awaiting_ack() const noexcept { return awaiting_ack_; }
  const CosProducerCounters& counters() const noexcept { return counters_; }

 private:
  std::vector<std::uint8_t> produce(TimePoint now);
  Duration ack_timer() const noexcept;
  // When the next heartbeat or cycle is due; none with an EPR of 0.
  std::optional<TimePoint> next_production() const noexcept;

  CosProduction settings_;
  std::vector<std::uint8_t> data_;
  std::vector<std::uint8_t> awaiting_;  // the message waiting for its acknowledgment
  TimePoint last_production_;
  bool change_pending_ = false;  // a change held back by the inhibit time
  bool awaiting_ack_ = false;
  std::uint8_t retries_left_ = 0;
  TimePoint ack_deadline_{};
  CosProducerCounters counters_;
};

}  // namespace dnbridge::sim
