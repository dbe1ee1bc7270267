#pragma once
// A node's poll connection (Connection 2): its allocation and EPR as the
// start-up makes them, its slots, the outputs and idle flag it carries, the
// poll in flight and its response, the strays of the idle poll before a
// Release, and the silence its 4 x EPR watchdog measures. Node owns one and
// decides what an answer, a bad answer or a silence leads to.
#include <cstdint>

#include "bridge/can/frame_sink.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/io_connection.hpp"
#include "bridge/devicenet/master/node_state.hpp"
#include "bridge/devicenet/master/scan_list.hpp"
#include "bridge/devicenet/wire/fragmentation.hpp"

namespace dnbridge::devicenet {

class PollConnection {
 public:
  // A response, whole: reported by on_response().
  class Listener {
   public:
    virtual ~Listener() = default;
    // A response of the produced size, or an empty one to an idle poll;
    // `late`: no poll was waiting for it (it timed out, or a bad answer
    // ended the wait). The connection has taken it as answered.
    virtual void on_poll_answer(Bytes inputs, bool late, TimePoint now) = 0;
    // A response of another size, or fragments out of order.
    virtual void on_bad_poll_answer(NodeError::Kind kind, std::uint32_t got, TimePoint now) = 0;
  };

  // `config` and `port` are read when used; `counters` are the node's.
  PollConnection(const NodeConfig& config, const ScannerConfig& port, can::FrameSink& sink,
                 NodeCounters& counters, Listener& listener);

  IoAllocation& allocation() { return allocation_; }
  const IoAllocation& allocation() const { return allocation_; }

  // The expected packet rate in force: the device's, once its Set answered.
  Duration epr() const { return epr_; }
  void set_epr(Duration epr) { epr_ = epr; }

  // --- slots ---
  // The node polls at phase + k * poll period.
  void set_phase(TimePoint phase) { phase_ = phase; }
  // Polling begins: nothing outstanding, the watchdog from `now`, the next
  // slot the first at or after `now`. The first poll is send()'s.
  void start(TimePoint now);
  // No more slots, deferred polls or response waits (the node left online).
  void stop();
  // No more slots; a poll in flight is still waited for (shutdown).
  void stop_slots() { next_slot_ = kNever; }
  // A new start-up attempt: its Allocate may be retried once more, and the
  // answers to an idle poll that did not come by now are not coming.
  void begin_attempt() {
    allocation_.release_tried = false;
    strays_ = 0;
  }
  TimePoint next_slot() const { return next_slot_; }
  // Serves the next slot now, ahead of time; the slot after it is next.
  // Nothing while a poll is unanswered: the slot is then served at its time.
  void serve_ahead(TimePoint now);
  // Serves a slot that is due, and the poll held back by the minimum gap
  // once the gap is over.
  void on_timer(TimePoint now);
  // The earliest of the next slot, the held-back poll and the watchdog;
  // meaningful while polling (from start() until stop() or stop_slots()).
  TimePoint timers_deadline() const;

  // --- outputs ---
  // New outputs (the consumed size: checked by the node); true when they
  // change what the next poll carries.
  bool set_outputs(Bytes data);
  bool set_idle(bool idle);
  // Idle, to be sent: the shutdown's last poll.
  void force_idle();
  bool idle() const { return idle_; }
  // The outputs or the idle flag were set anew since the last poll.
  bool dirty() const { return dirty_; }
  // Outputs and idle flag of the last poll the device answered.
  Bytes applied_outputs() const { return applied_outputs_.view(); }
  bool applied_idle() const { return applied_idle_; }

  // --- polls ---
  // A poll with the outputs in force (idle: no data) now.
  void send(TimePoint now);
  // The poll for outputs that changed: now, or at the end of the minimum gap
  // after the last one (NodeConfig::immediate_poll_min_gap).
  void send_for_change(TimePoint now);
  // One idle poll now, whatever the outputs in force, before the connections
  // go: the device applies its idle action, not whatever it does on a
  // Release (the manual names nothing). Its answer, and that to a poll
  // outstanding, are strays (take_stray()): the node is not online when
  // they come.
  void send_idle_before_release(TimePoint now);
  bool outstanding() const { return outstanding_; }
  // When the poll outstanding is given up; kNever without one.
  TimePoint response_deadline() const { return outstanding_ ? response_deadline_ : kNever; }
  // The poll outstanding went unanswered: the next one is a retry.
  void give_up();
  // The poll outstanding is no longer waited for (a bad answer, a release).
  void drop_outstanding();
  // A bad answer in a row more: their count (a good answer ends the run).
  unsigned count_error() { return ++consecutive_errors_; }
  // Since the last response.
  Duration silence(TimePoint now) const { return now - last_response_; }
  // 4 x EPR without a response: the device has dropped the connection.
  bool watchdog_expired(TimePoint now) const { return silence(now) >= 4 * epr_; }

  // --- responses ---
  // A frame of a response: reported to the listener once whole.
  void on_response(Bytes payload, TimePoint now);
  // Answers to the idle poll before a release still to come.
  bool strays_expected() const { return strays_ > 0; }
  // A frame of one of them: counted off once its message is complete.
  void take_stray(Bytes payload);

 private:
  TimePoint slot_after(TimePoint after) const;

  const NodeConfig& config_;
  const ScannerConfig& port_;
  can::FrameSink& sink_;
  NodeCounters& counters_;
  Listener& listener_;

  IoAllocation allocation_;
  Duration epr_{};

  TimePoint phase_{};
  TimePoint next_slot_ = kNever;
  TimePoint response_deadline_ = kNever;
  TimePoint last_response_{};
  bool outstanding_ = false;
  bool unanswered_ = false;  // the last poll timed out: the next is a retry
  bool dirty_ = false;
  // The last poll sent early because the outputs changed, and the time of the
  // one held back until the minimum gap after it has elapsed (kNever: none).
  TimePoint last_change_poll_ = TimePoint::min();
  TimePoint deferred_ = kNever;
  bool idle_ = true;  // no outputs until the layer above sets them
  unsigned consecutive_errors_ = 0;
  unsigned strays_ = 0;  // answers to expect to an idle poll before a Release
  InlineBytes<kMaxIoMessageSize> outputs_;
  InlineBytes<kMaxIoMessageSize> sent_outputs_;
  bool sent_idle_ = true;
  InlineBytes<kMaxIoMessageSize> applied_outputs_;
  bool applied_idle_ = true;
  IoReassembler reassembler_{kMaxIoMessageSize};
};

}  // namespace dnbridge::devicenet
