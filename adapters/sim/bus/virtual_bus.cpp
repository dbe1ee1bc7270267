#include "adapters/sim/bus/virtual_bus.hpp"

#include <algorithm>

namespace dnbridge::sim {

class VirtualBus::NodeSink final : public can::FrameSink {
 public:
  NodeSink(VirtualBus& bus, NodeHandle node) noexcept : bus_(bus), node_(node) {}
  void send(const can::CanFrame& frame, TimePoint now) override { bus_.send(node_, frame, now); }

 private:
  VirtualBus& bus_;
  NodeHandle node_;
};

struct VirtualBus::Node {
  Node(VirtualBus& bus, NodeHandle handle, BusPort& p) : port(&p), sink(bus, handle) {}
  BusPort* port;
  bool attached = true;
  std::deque<Queued> tx;
  NodeSink sink;
};

namespace {
// No node is ever given this handle: the discarding sink sends as it.
constexpr NodeHandle kNoNode{0xFFFF'FFFF};
}  // namespace

VirtualBus::VirtualBus(BusConfig config)
    : config_(config),
      faults_(config.seed),
      discard_sink_(std::make_unique<NodeSink>(*this, kNoNode)) {}

VirtualBus::~VirtualBus() = default;

VirtualBus::Node* VirtualBus::find(NodeHandle node) noexcept {
  return node.index < nodes_.size() ? nodes_[node.index].get() : nullptr;
}

const VirtualBus::Node* VirtualBus::find(NodeHandle node) const noexcept {
  return node.index < nodes_.size() ? nodes_[node.index].get() : nullptr;
}

NodeHandle VirtualBus::attach(BusPort& port) {
  const NodeHandle handle{static_cast<std::uint32_t>(nodes_.size())};
  nodes_.push_back(std::make_unique<Node>(*this, handle, port));
  return handle;
}

Status VirtualBus::detach(NodeHandle node) {
  Node* n = find(node);
  if (n == nullptr) return Errc::kOutOfRange;
  if (!n->attached) return {};
  n->attached = false;
  // A node that loses power loses what its controller had queued.
  stats_.dropped_detached += n->tx.size();
  n->tx.clear();
  const auto from_node = [node](const Held& h) { return h.sender == node; };
  stats_.dropped_detached +=
      static_cast<std::uint64_t>(std::count_if(held_.begin(), held_.end(), from_node));
  held_.erase(std::remove_if(held_.begin(), held_.end(), from_node), held_.end());
  // A frame cut off mid-way ends in an error frame on a real bus; here it
  // keeps the medium for its full length and reaches nobody.
  if (in_flight_ && in_flight_->sender == node) in_flight_->aborted = true;
  return {};
}

Status VirtualBus::reattach(NodeHandle node) {
  Node* n = find(node);
  if (n == nullptr) return Errc::kOutOfRange;
  n->attached = true;
  return {};
}

bool VirtualBus::attached(NodeHandle node) const noexcept {
  const Node* n = find(node);
  return n != nullptr && n->attached;
}

can::FrameSink& VirtualBus::sink(NodeHandle node) noexcept {
  Node* n = find(node);
  return n != nullptr ? static_cast<can::FrameSink&>(n->sink) : *discard_sink_;
}

std::size_t VirtualBus::queued_frames(NodeHandle node) const noexcept {
  const Node* n = find(node);
  return n != nullptr ? n->tx.size() : 0;
}

std::uint64_t VirtualBus::frames_with_id(std::uint32_t id) const noexcept {
  return id <= can::kMaxStandardId ? per_id_[id] : 0;
}

void VirtualBus::send(NodeHandle node, const can::CanFrame& frame, TimePoint now) {
  Node* n = find(node);
  if (n == nullptr || !n->attached) {
    ++stats_.dropped_detached;
    return;
  }
  ++stats_.queued;
  // Nothing is scheduled in the past: a late caller's frame is ready now.
  const TimePoint t = std::max(now, time_);
  can::CanFrame f = frame;
  const FaultResult fault = faults_.apply(f, node);
  switch (fault.outcome) {
    case FaultOutcome::kPass:
      break;
    case FaultOutcome::kDrop:
      ++stats_.fault_dropped;
      return;
    case FaultOutcome::kDelay:
      // Held aside, not in the queue: later frames of the node may overtake it.
      ++stats_.fault_delayed;
      held_.push_back(Held{f, t + fault.delay, next_seq_++, node});
      return;
    case FaultOutcome::kCorrupt:
      ++stats_.fault_corrupted;
      break;
  }
  enqueue(node, f, t);
}

void VirtualBus::enqueue(NodeHandle sender, const can::CanFrame& frame, TimePoint ready) {
  Node* n = find(sender);
  if (n == nullptr || !n->attached) {
    ++stats_.dropped_detached;
    return;
  }
  if (config_.tx_queue_capacity != 0 && n->tx.size() >= config_.tx_queue_capacity) {
    ++stats_.queue_overflows;
    return;
  }
  // FIFO per node: a frame is never ready before the one queued ahead of it.
  if (!n->tx.empty()) ready = std::max(ready, n->tx.back().ready);
  n->tx.push_back(Queued{frame, ready, next_seq_++});
}

std::optional<std::size_t> VirtualBus::earliest_held() const noexcept {
  std::optional<std::size_t> best;
  for (std::size_t i = 0; i < held_.size(); ++i) {
    const Held& h = held_[i];
    if (!best || h.release < held_[*best].release ||
        (h.release == held_[*best].release && h.seq < held_[*best].seq)) {
      best = i;
    }
  }
  return best;
}

TimePoint VirtualBus::next_event() const noexcept {
  TimePoint next = kNever;
  if (const auto h = earliest_held()) next = held_[*h].release;
  if (in_flight_) {
    next = std::min(next, in_flight_->end);
  } else {
    for (const auto& n : nodes_) {
      if (n->attached && !n->tx.empty()) next = std::min(next, n->tx.front().ready);
    }
  }
  // A frame that waited for a busy bus is due as soon as the bus is free.
  return next == kNever ? kNever : std::max(next, time_);
}

void VirtualBus::advance(TimePoint now) {
  std::size_t steps = 0;
  for (;;) {
    const TimePoint t = next_event();
    if (t == kNever || t > now) break;
    if (steps++ >= config_.max_steps_per_advance) {
      // What is left is due at or before `now`; time stays where it stopped.
      ++stats_.step_limit_hits;
      return;
    }
    time_ = t;
    step(t);
  }
  if (now > time_ && now != kNever) time_ = now;
}

// One event at time t. At equal times a frame ending comes first (its
// receivers may queue answers), then delayed frames are released, then the
// next frame goes out, so everything ready at t takes part in arbitration.
void VirtualBus::step(TimePoint t) {
  if (in_flight_ && in_flight_->end <= t) {
    complete_transmission();
    return;
  }
  if (const auto h = earliest_held(); h && held_[*h].release <= t) {
    const Held held = held_[*h];
    held_.erase(held_.begin() + static_cast<std::ptrdiff_t>(*h));
    enqueue(held.sender, held.frame, held.release);
    return;
  }
  if (!in_flight_) start_transmission(t);
}

void VirtualBus::start_transmission(TimePoint t) {
  // Ideal mode: the oldest ready frame of all nodes. Timed mode: CAN
  // arbitration, lowest identifier wins; equal identifiers from two nodes would
  // collide on a real bus (bit error in the data) and are counted, with the
  // lower handle winning here.
  Node* winner = nullptr;
  std::size_t winner_index = 0;
  std::uint64_t same_id = 0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    Node* n = nodes_[i].get();
    if (!n->attached || n->tx.empty() || n->tx.front().ready > t) continue;
    const Queued& q = n->tx.front();
    if (winner == nullptr) {
      winner = n;
      winner_index = i;
      same_id = 1;
      continue;
    }
    const Queued& w = winner->tx.front();
    if (timed()) {
      if (q.frame.id < w.frame.id) {
        winner = n;
        winner_index = i;
        same_id = 1;
      } else if (q.frame.id == w.frame.id) {
        ++same_id;
      }
    } else if (q.seq < w.seq) {
      winner = n;
      winner_index = i;
    }
  }
  if (winner == nullptr) return;
  if (timed()) stats_.collisions += same_id - 1;

  const can::CanFrame frame = winner->tx.front().frame;
  winner->tx.pop_front();
  const NodeHandle sender{static_cast<std::uint32_t>(winner_index)};
  const std::uint32_t bits = can::frame_bits(frame);
  ++stats_.transmitted;
  stats_.bits += bits;
  if (!timed()) {
    deliver(frame, sender, t);
    return;
  }
  in_flight_ = InFlight{frame, sender, t, t + can::bits_duration(bits, config_.bitrate), false};
}

void VirtualBus::complete_transmission() {
  const InFlight f = *in_flight_;
  in_flight_.reset();
  stats_.busy_time += f.end - f.start;
  if (const TimePoint from = std::max(f.start, window_start_); f.end > from)
    window_busy_ += f.end - from;
  if (f.aborted) {
    ++stats_.aborted;
    return;
  }
  deliver(f.frame, f.sender, f.end);
}

void VirtualBus::deliver(const can::CanFrame& frame, NodeHandle sender, TimePoint rx_time) {
  // Nodes attached from inside on_frame were not on the bus when the frame was.
  const std::size_t count = nodes_.size();
  bool acknowledged = false;
  for (std::size_t i = 0; i < count; ++i) {
    if (i != sender.index && nodes_[i]->attached) acknowledged = true;
  }
  if (tap_) tap_(WireFrame{frame, sender, rx_time, acknowledged});
  if (!acknowledged) {
    ++stats_.unacknowledged;
    return;
  }
  ++stats_.delivered;
  ++per_id_[frame.id & can::kMaxStandardId];
  for (std::size_t i = 0; i < count; ++i) {
    // Re-read each time: an earlier receiver may have detached this one.
    Node& n = *nodes_[i];
    if (i == sender.index || !n.attached) continue;
    ++stats_.receptions;
    n.port->on_frame(frame, rx_time);
  }
}

double VirtualBus::bus_load(TimePoint now) const noexcept {
  if (now <= window_start_) return 0.0;
  Duration busy = window_busy_;
  if (in_flight_) {
    const TimePoint from = std::max(in_flight_->start, window_start_);
    const TimePoint to = std::min(in_flight_->end, now);
    if (to > from) busy += to - from;
  }
  return static_cast<double>(busy.count()) / static_cast<double>((now - window_start_).count());
}

void VirtualBus::reset_load_window(TimePoint now) noexcept {
  window_start_ = now;
  window_busy_ = Duration::zero();
}

}  // namespace dnbridge::sim
