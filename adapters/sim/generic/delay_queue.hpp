#pragma once
// What a slow device holds before it sends: items each due at a time, in a
// fixed-capacity first-in first-out queue. Sans-IO, as the slave is: the
// owner asks for deadline() and hands in `now`; nothing allocates.
#include <array>
#include <cstddef>

#include "bridge/common/time.hpp"

namespace dnbridge::sim {

template <class T, std::size_t N>
class DelayQueue {
 public:
  static_assert(N > 0);

  // Keeps `item` until `due`; false (nothing kept) when the queue is full.
  bool push(TimePoint due, const T& item) noexcept {
    if (size_ == N) return false;
    Slot& s = slots_[(head_ + size_) % N];
    s.due = due;
    s.item = item;
    ++size_;
    return true;
  }

  // The first item leaves first even if a later one is due earlier: items
  // pushed with one delay leave in the order they came, which is the point.
  TimePoint deadline() const noexcept { return size_ == 0 ? kNever : slots_[head_].due; }

  // Moves the first item into `out` if it is due at `now`.
  bool pop_due(TimePoint now, T& out) noexcept {
    if (size_ == 0 || slots_[head_].due > now) return false;
    out = slots_[head_].item;
    head_ = (head_ + 1) % N;
    --size_;
    return true;
  }

  bool empty() const noexcept { return size_ == 0; }
  std::size_t size() const noexcept { return size_; }
  void clear() noexcept {
    head_ = 0;
    size_ = 0;
  }

 private:
  struct Slot {
    TimePoint due{};
    T item{};
  };
  std::array<Slot, N> slots_{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
};

}  // namespace dnbridge::sim
