#pragma once
// Driving one simulated CDN127 frame by frame with a fake clock, as the
// simulator tests do: a sink that records what it sends, and its timers run
// up to a time as an event loop would.
#include <algorithm>
#include <utility>
#include <vector>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "bridge/can/frame_sink.hpp"

namespace dnbridge::test {

class RecordingSink : public can::FrameSink {
 public:
  void send(const can::CanFrame& f, TimePoint) override { frames.push_back(f); }
  std::vector<can::CanFrame> take() { return std::exchange(frames, {}); }
  std::vector<can::CanFrame> frames;
};

// Runs `slave`'s timers up to now + d and leaves `now` there.
inline void advance(sim::Cdn127Slave& slave, TimePoint& now, Duration d) {
  const TimePoint end = now + d;
  for (int guard = 0; guard < 10000 && slave.next_deadline() <= end; ++guard) {
    now = std::max(now, slave.next_deadline());
    slave.on_timer(now);
  }
  now = end;
}

}  // namespace dnbridge::test
