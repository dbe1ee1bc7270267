#pragma once
// A node's input connection as the master runs it: change of state or
// cyclic (Connection 4), or bit-strobe (Connection 3). Its allocation, the
// settings the start-up asks and learns (EPR, the Acknowledge Handler's
// timer and retry limit), and from the Set of its EPR on the consumer of its
// messages: their framing, the acknowledgments and the 4 x EPR watchdog.
// Node owns one, counts the bad messages in a row here, and decides what
// they or a silence lead to.
#include <cstdint>
#include <optional>
#include <string>

#include "bridge/can/frame_sink.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/cos_consumer.hpp"
#include "bridge/devicenet/master/io_connection.hpp"
#include "bridge/devicenet/master/node_state.hpp"
#include "bridge/devicenet/master/scan_list.hpp"
#include "bridge/devicenet/wire/fragmentation.hpp"

namespace dnbridge::devicenet {

class InputLink {
 public:
  // Messages, whole: reported by on_message().
  class Listener {
   public:
    virtual ~Listener() = default;
    // A message taken that is not the device's retry of the one before.
    virtual void on_inputs(Bytes data, TimePoint now) = 0;
    // A message of another size, or fragments out of order.
    virtual void on_bad_inputs(NodeError::Kind kind, std::uint32_t got, TimePoint now) = 0;
  };

  // `config` is read when used (the node's); `counters` are the node's.
  InputLink(const NodeConfig& config, can::FrameSink& sink, NodeCounters& counters,
            Listener& listener);

  // The connection as configured; nullptr for a node without one.
  const InputConnection* configured() const {
    return config_.profile.input_connection ? &*config_.profile.input_connection : nullptr;
  }

  IoAllocation& allocation() { return allocation_; }
  const IoAllocation& allocation() const { return allocation_; }
  // Its Allocate's choice (acknowledgment suppression included), and its
  // bits without suppression (for Release); 0 without a connection.
  std::uint8_t choice() const;
  std::uint8_t connection_bits() const;
  // The EPR asked (a bit-strobe connection takes the node's).
  Duration epr_asked() const;

  // --- the start-up ---
  // A new attempt: what an earlier one learnt is forgotten.
  void begin_attempt();
  // The settings asked, as the start-up learns the device's (the
  // consumer's from start_consuming() on).
  void set_ack_timer(Duration timer) { asked_.ack_timer = timer; }
  void set_retry_limit(std::uint8_t limit) { asked_.retry_limit = limit; }
  // Its timer or retry limit refused: the defaults are taken.
  void note_ack_handler_unread() { ack_handler_unread_ = true; }
  // Why the device's own path may be the one in force ("; Set of ...
  // refused: ..."), for the reasons; empty when its Set was taken.
  const std::string& path_refusal() const { return path_refusal_; }
  void set_path_refusal(std::string text) { path_refusal_ = std::move(text); }
  // Setting its EPR starts production: messages are taken from here on (a
  // first one may come before the answer).
  void start_consuming(TimePoint now);
  // The EPR the device returned (the watchdog runs on it).
  void set_epr(Duration epr);

  // --- running ---
  bool consuming() const { return consumer_.has_value(); }
  // The settings in force; empty while not consuming.
  std::optional<CosSettings> settings() const;
  void stop() { consumer_.reset(); }
  // Online: no bad messages in a row yet.
  void reset_errors() { errors_in_a_row_ = 0; }
  // A frame of a message: reported to the listener once whole. Only while
  // consuming().
  void on_message(Bytes payload, TimePoint now);
  // A bad message in a row more: their count (a good message ends the run).
  unsigned count_error() { return ++errors_in_a_row_; }
  unsigned errors_in_a_row() const { return errors_in_a_row_; }
  // When nothing has come for 4 x EPR; kNever while not consuming.
  TimePoint watchdog_deadline() const;
  // At or after watchdog_deadline(): true, once, when the connection is lost.
  bool watchdog_expired(TimePoint now);
  TimePoint last_message() const { return consumer_ ? consumer_->last_message() : TimePoint{}; }
  // The last message's data; empty before one.
  Bytes last_data() const;
  // How it runs, for the online reason: "; inputs cyclic (EPR 500 ms, ...)";
  // empty while not consuming.
  std::string describe() const;

 private:
  const NodeConfig& config_;
  can::FrameSink& sink_;
  NodeCounters& counters_;
  Listener& listener_;

  IoAllocation allocation_;
  CosSettings asked_;
  bool ack_handler_unread_ = false;
  std::string path_refusal_;
  std::optional<CosConsumer> consumer_;
  IoReassembler reassembler_{kMaxIoMessageSize};
  unsigned errors_in_a_row_ = 0;
};

}  // namespace dnbridge::devicenet
