#pragma once
// When a port's PortStatus is published: at once after a change it shows
// (the master's or a node's state, the bus's, a reload, an unconfigured
// node heard), and otherwise once per status period.
#include <algorithm>

#include "bridge/common/time.hpp"

namespace dnbridge::port {

class PortStatusSchedule {
 public:
  explicit PortStatusSchedule(Duration period) : period_(period) {}

  // The first period begins.
  void start(TimePoint now) { last_ = now; }
  // A change the PortStatus shows, published at the next pass; `at`, when
  // given, is the time of the event (the sample's source time).
  void changed() { changed_ = true; }
  void changed(TimePoint at) {
    changed_ = true;
    event_time_ = at;
  }
  bool due(TimePoint now, bool force) const { return force || changed_ || now >= last_ + period_; }
  // The sample's source time: the last event's, when later than `now`.
  TimePoint source_time(TimePoint now) const { return std::max(now, event_time_); }
  void published(TimePoint now) {
    last_ = now;
    changed_ = false;
  }
  // At once after a change (the last PortStatus's time, already past);
  // otherwise a period after it.
  TimePoint next_due() const { return changed_ ? last_ : last_ + period_; }

 private:
  Duration period_;
  TimePoint last_{};
  TimePoint event_time_{};
  bool changed_ = true;  // the first pass publishes
};

}  // namespace dnbridge::port
