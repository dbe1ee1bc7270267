#pragma once
// The master's end of a slave's change-of-state or cyclic connection
// (instance 4 of the predefined master/slave set), message by message:
//
// - The slave produces on Group 1 message 0xD: on a change of its data (no
//   more often than its production inhibit time) and at least once per
//   expected packet rate (EPR) as a heartbeat (change of state), or every
//   EPR (cyclic).
// - Unless the connection was allocated with acknowledgment suppressed
//   (allocation choice bit 0x40), the master acknowledges each message on
//   Group 2 message 2 (ack_frame). A device that gets no acknowledgment
//   sends the message again at its acknowledge timer, up to its retry limit
//   (Acknowledge Handler object, class 0x2B, attributes 1 and 2: 20 ms and 1
//   by default; LUFP9 manual, appendix D, shared/seeds/000).
// - Nothing for 4 × EPR is the connection's loss (its inactivity watchdog),
//   handled as a poll timeout is.
//
// What the master sees of the device's retries: the same data again, k
// acknowledge timers (plus `ack_slack`) at most after the message it
// repeats for its k-th retry, and more than `ack_slack` sooner than an EPR
// after it: a change of state cannot be that (it needs a change), nor a
// heartbeat or cycle (it comes an EPR after). With an EPR no longer than
// the acknowledge timer, a heartbeat supersedes a retry before it is due,
// and nothing counts. Counted as repeats, acknowledged as
// any message; none with acknowledgment suppressed (nothing is retried).
// An EPR of 0 means no watchdog (as the Connection object's 0 is read;
// UNVERIFIED).
//
// Sans-IO and clockless: time comes in as arguments.
#include <cstdint>
#include <vector>

#include "bridge/can/can_frame.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::devicenet {

struct CosSettings {
  Duration expected_packet_rate = milliseconds(1000);  // as the device returned it
  bool ack_suppressed = false;
  Duration ack_timer = milliseconds(20);  // the device's, read from class 0x2B
  std::uint8_t retry_limit = 1;           // the device's, read from class 0x2B
  // Bus and scheduling time on top of the acknowledge timer for a repeat.
  Duration ack_slack = milliseconds(5);
};

struct CosCounters {
  std::uint64_t messages = 0;   // every message taken, repeats included
  std::uint64_t acks_sent = 0;  // acknowledgments asked for (on_message)
  std::uint64_t repeats = 0;    // the device's retries seen (above)
  std::uint64_t losses = 0;     // 4 × EPR without a message
};

class CosConsumer {
 public:
  CosConsumer(MacId slave, CosSettings settings, TimePoint established);

  struct Taken {
    bool repeat = false;       // the device's retry of the message before
    bool acknowledge = false;  // send ack_frame() now
  };
  // A message of the connection, its data as reassembled.
  Taken on_message(Bytes data, TimePoint now);

  // When nothing has come for 4 × EPR (never with an EPR of 0); after it,
  // lost() until a message.
  TimePoint watchdog_deadline() const noexcept {
    if (settings_.expected_packet_rate <= Duration::zero()) return kNever;
    return last_ + 4 * settings_.expected_packet_rate;
  }
  // Call when now >= watchdog_deadline(): true (once per loss) when the
  // connection is lost.
  bool check_watchdog(TimePoint now);
  bool lost() const noexcept { return lost_; }
  // The last message taken (the connection's establishment before one).
  TimePoint last_message() const noexcept { return last_; }

  // The master's acknowledgment: Group 2 message 2 to the slave, no data
  // (the ack carries none; a device that wanted some is UNVERIFIED).
  can::CanFrame ack_frame() const noexcept;

  // The EPR the device returned for the one asked (the watchdog runs on it).
  void set_expected_packet_rate(Duration epr) noexcept { settings_.expected_packet_rate = epr; }

  const CosSettings& settings() const noexcept { return settings_; }
  const CosCounters& counters() const noexcept { return counters_; }
  const std::vector<std::uint8_t>& last_data() const noexcept { return data_; }

 private:
  MacId slave_;
  CosSettings settings_;
  TimePoint last_;
  TimePoint original_;  // of the last message that was not a repeat
  bool have_data_ = false;
  bool lost_ = false;
  std::vector<std::uint8_t> data_;
  std::uint8_t repeats_in_a_row_ = 0;
  CosCounters counters_;
};

}  // namespace dnbridge::devicenet
