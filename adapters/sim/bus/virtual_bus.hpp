#pragma once
// An in-process CAN bus for simulations and integration tests. Sans-IO: no
// threads, no clock; the caller passes the time and calls advance().
//
// Two modes, chosen by the bit rate:
//  - 0, "ideal": a frame is delivered at the time it was sent, in send order.
//  - 125k/250k/500k, "timed": one shared medium. When it is idle, arbitration
//    picks the lowest identifier among the heads of the nodes' transmit queues
//    (FIFO per node); the frame occupies the bus for can::frame_duration() and is
//    delivered to every other attached node at its end.
// A frame nobody else hears is not acknowledged: it is counted and dropped. A
// real controller would retransmit it until an error counter took it off the
// bus; tests that want that behaviour should look at the counter instead.
//
// A tap (set_tap) sees every frame that completed on the wire, in wire order,
// for captures and traces.
//
// Power cycling is the node's business: it detaches (sends and receives
// nothing, its queued frames are lost), resets itself and reattaches.
#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "adapters/sim/bus/fault_injection.hpp"
#include "bridge/can/can_frame.hpp"
#include "bridge/can/can_timing.hpp"
#include "bridge/can/frame_sink.hpp"
#include "bridge/common/result.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::sim {

// What a node on the bus receives through.
class BusPort {
 public:
  virtual ~BusPort() = default;
  // Every frame another node put on the bus. It may send through its sink:
  // the frame is queued and handled after this call returns, never inside it.
  // It may detach or reattach nodes, which takes effect at once (a node
  // detached here does not receive this frame if it has not yet).
  virtual void on_frame(const can::CanFrame& frame, TimePoint rx_time) = 0;
};

struct BusConfig {
  std::uint32_t bitrate = 0;  // 0: ideal; can::kBitrate125k/250k/500k: timed
  std::uint64_t seed = FaultInjector::kDefaultSeed;
  // Events one advance() call handles at most, so that two nodes answering
  // each other at the same instant cannot loop for ever. Reaching it is
  // counted; what is left stays pending for the next call.
  std::size_t max_steps_per_advance = 100000;
  // Frames a node's transmit queue holds; 0 = unbounded.
  std::size_t tx_queue_capacity = 0;
};

struct BusStats {
  std::uint64_t queued = 0;       // frames accepted by send()
  std::uint64_t transmitted = 0;  // frames that went on the wire (acknowledged or not)
  std::uint64_t delivered = 0;    // transmitted frames at least one node acknowledged
  std::uint64_t receptions = 0;   // on_frame calls
  std::uint64_t bits = 0;         // frame_bits of every transmitted frame
  Duration busy_time{};           // time the medium was occupied (timed mode)
  // Errors and anomalies.
  std::uint64_t unacknowledged = 0;    // no other attached node at the end of the frame
  std::uint64_t collisions = 0;        // arbitration between equal identifiers of different nodes
  std::uint64_t aborted = 0;           // sender detached while its frame was on the wire
  std::uint64_t dropped_detached = 0;  // sent by, or queued in, a detached node
  std::uint64_t queue_overflows = 0;   // transmit queue full
  std::uint64_t step_limit_hits = 0;   // advance() stopped at max_steps_per_advance
  // Fault injection.
  std::uint64_t fault_dropped = 0;
  std::uint64_t fault_delayed = 0;
  std::uint64_t fault_corrupted = 0;
};

// A frame as a bus analyser clamped onto the cable sees it.
struct WireFrame {
  can::CanFrame frame;  // as transmitted, after fault injection (a corrupted frame as corrupted)
  NodeHandle sender;
  TimePoint end;  // end of frame (ideal mode: the time it went out)
  // False when no other node was attached to acknowledge it. Such frames are
  // included: an analyser on the cable sees them (its own controller would
  // even acknowledge them), and a node alone on the bus, e.g. a master
  // checking its MAC before any slave is powered, is what an engineer wants to
  // see. Frames aborted mid-way (sender detached) are not: they never complete
  // and a real analyser shows an error frame instead.
  bool acknowledged;
};

class VirtualBus {
 public:
  // Called once per completed frame, before any node receives it, so that a
  // capture lists frames in wire order. It must not send, attach or detach.
  using Tap = std::function<void(const WireFrame&)>;

  explicit VirtualBus(BusConfig config = {});
  ~VirtualBus();
  VirtualBus(const VirtualBus&) = delete;
  VirtualBus& operator=(const VirtualBus&) = delete;

  // `port` must outlive the bus, or stay detached once it is gone.
  NodeHandle attach(BusPort& port);
  // Unknown handles give kOutOfRange.
  Status detach(NodeHandle node);
  Status reattach(NodeHandle node);
  bool attached(NodeHandle node) const noexcept;

  // The sink through which `node` sends: send(frame, now) queues the frame in
  // its transmit queue. Valid as long as the bus; an unknown handle gets a sink
  // that discards (counted as dropped_detached).
  can::FrameSink& sink(NodeHandle node) noexcept;
  void send(NodeHandle node, const can::CanFrame& frame, TimePoint now);

  // The time of the next thing the bus will do, kNever when nothing is pending.
  TimePoint next_event() const noexcept;
  // Completes and delivers everything due up to `now`, including frames sent
  // from on_frame meanwhile.
  void advance(TimePoint now);

  // Latest time the bus has processed.
  TimePoint time() const noexcept { return time_; }
  bool busy() const noexcept { return in_flight_.has_value(); }
  std::uint32_t bitrate() const noexcept { return config_.bitrate; }
  bool timed() const noexcept { return config_.bitrate != 0; }
  std::size_t queued_frames(NodeHandle node) const noexcept;

  // One tap at a time; setting one replaces the previous, an empty one removes it.
  void set_tap(Tap tap) { tap_ = std::move(tap); }

  FaultInjector& faults() noexcept { return faults_; }
  const BusStats& stats() const noexcept { return stats_; }
  // Acknowledged frames per identifier.
  std::uint64_t frames_with_id(std::uint32_t id) const noexcept;

  // Fraction of [window start, now] the medium was busy; the window starts at
  // time zero or at the last reset. `now` is expected at or after time().
  double bus_load(TimePoint now) const noexcept;
  void reset_load_window(TimePoint now) noexcept;

 private:
  class NodeSink;
  struct Queued {
    can::CanFrame frame;
    TimePoint ready;
    std::uint64_t seq;
  };
  struct Held {
    can::CanFrame frame;
    TimePoint release;
    std::uint64_t seq;
    NodeHandle sender;
  };
  struct Node;
  struct InFlight {
    can::CanFrame frame;
    NodeHandle sender;
    TimePoint start;
    TimePoint end;
    bool aborted = false;
  };

  Node* find(NodeHandle node) noexcept;
  const Node* find(NodeHandle node) const noexcept;
  void enqueue(NodeHandle sender, const can::CanFrame& frame, TimePoint ready);
  void step(TimePoint t);
  void start_transmission(TimePoint t);
  void complete_transmission();
  void deliver(const can::CanFrame& frame, NodeHandle sender, TimePoint rx_time);
  std::optional<std::size_t> earliest_held() const noexcept;

  BusConfig config_;
  FaultInjector faults_;
  std::vector<std::unique_ptr<Node>> nodes_;
  std::unique_ptr<NodeSink> discard_sink_;
  std::vector<Held> held_;  // frames delayed by a fault rule
  std::optional<InFlight> in_flight_;
  TimePoint time_{};
  std::uint64_t next_seq_ = 0;
  BusStats stats_;
  std::array<std::uint64_t, can::kMaxStandardId + 1> per_id_{};
  Tap tap_;
  TimePoint window_start_{};
  Duration window_busy_{};
};

}  // namespace dnbridge::sim
