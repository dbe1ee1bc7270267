#include "adapters/sim/world/sim_world.hpp"

#include <algorithm>
#include <stdexcept>

namespace dnbridge::sim {
namespace {
// Steps at one instant beyond which the simulation is taken to be spinning (a
// deadline that never moves): a defect to report, not to wait out.
constexpr std::size_t kMaxStepsAtOneTime = 1'000'000;
}  // namespace

SimWorld::SimWorld(BusConfig config, TimePoint start) : bus_(config), now_(start) {}

void SimWorld::add(SimEndpoint& endpoint) { endpoints_.push_back(&endpoint); }

void SimWorld::remove(SimEndpoint& endpoint) {
  endpoints_.erase(std::remove(endpoints_.begin(), endpoints_.end(), &endpoint), endpoints_.end());
}

TimePoint SimWorld::next_event() const {
  TimePoint t = bus_.next_event();
  for (const auto* e : endpoints_) t = std::min(t, e->next_deadline());
  return t;
}

bool SimWorld::step(TimePoint limit) {
  TimePoint t = next_event();
  if (t > limit) return false;
  t = std::max(t, now_);  // a deadline already past runs now
  if (t == now_) {
    if (++same_time_steps_ > kMaxStepsAtOneTime) {
      throw std::logic_error("simulation does not advance: a deadline never moves");
    }
  } else {
    same_time_steps_ = 0;
  }
  now_ = t;
  bus_.advance(t);
  // Copy: an endpoint's timer may add or remove endpoints.
  const auto endpoints = endpoints_;
  for (auto* e : endpoints) {
    if (e->next_deadline() <= t) e->on_timer(t);
  }
  bus_.advance(t);
  return true;
}

void SimWorld::run_until(TimePoint until) {
  while (step(until)) {
  }
  if (until > now_) {
    now_ = until;
    bus_.advance(until);
  }
}

bool SimWorld::run_until(const std::function<bool()>& done, Duration timeout) {
  const TimePoint limit = now_ + timeout;
  if (done()) return true;
  while (step(limit)) {
    if (done()) return true;
  }
  run_until(limit);
  return done();
}

}  // namespace dnbridge::sim
