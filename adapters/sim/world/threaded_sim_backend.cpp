#include "adapters/sim/world/threaded_sim_backend.hpp"

#include <fmt/format.h>
#include <pthread.h>
#include <sys/prctl.h>

#include <chrono>
#include <ctime>
#include <stdexcept>

#include "adapters/port/steady_time.hpp"
#include "adapters/port/thread_name.hpp"
#include "adapters/sim/world/sim_rack.hpp"

namespace dnbridge::sim {

ThreadedSimBackend::ThreadedSimBackend(std::uint32_t bitrate,
                                       const std::vector<devicenet::MacId>& device_macs,
                                       LogSink* log)
    : bitrate_(bitrate),
      world_(BusConfig{bitrate}, port::steady_now()),
      handle_(world_.bus().attach(master_port_)) {
  for (auto mac : device_macs) {
    Logger device_log = log ? Logger(*log, fmt::format("sim {}", mac.value())) : Logger();
    devices_[mac.value()] = std::make_unique<SimSlave>(world_, sim::default_slave_options(mac),
                                                       world_.now(), std::move(device_log));
  }
  to_world_.reserve(64);
  to_port_.reserve(64);
  receiving_.reserve(64);
  delivered_.reserve(64);
  thread_ = std::thread([this] { run(); });
  port::name_thread(thread_, "sim bus");
  if (pthread_getcpuclockid(thread_.native_handle(), &sim_clock_) != 0) sim_clock_ = -1;
}

ThreadedSimBackend::~ThreadedSimBackend() {
  {
    std::lock_guard lock(world_mutex_);
    stop_ = true;
  }
  world_woken_.notify_one();
  thread_.join();
  (void)world_.bus().detach(handle_);
}

TimePoint ThreadedSimBackend::now() const { return port::steady_now(); }

SimSlave& ThreadedSimBackend::device(devicenet::MacId mac) {
  auto it = devices_.find(mac.value());
  if (it == devices_.end())
    throw std::out_of_range(fmt::format("no simulated device {}", mac.value()));
  return *it->second;
}

void ThreadedSimBackend::MasterSink::send(const can::CanFrame& frame, TimePoint now) {
  // Queued, as in a socket's send buffer; the world is woken for them when
  // the port waits (see wait()), so the frames of one turn of the port's loop
  // reach the bus together, at the times they were sent.
  owner_.candump_.frame(frame, port::CandumpLog::wall_now());
  std::lock_guard lock(owner_.world_mutex_);
  owner_.to_world_.emplace_back(frame, now);
}

void ThreadedSimBackend::MasterPort::on_frame(const can::CanFrame& frame, TimePoint rx_time) {
  owner_.delivered_.emplace_back(frame, rx_time);
}

void ThreadedSimBackend::post(std::function<void()> fn) {
  {
    std::lock_guard lock(world_mutex_);
    posted_.push_back(std::move(fn));
  }
  world_woken_.notify_one();
}

void ThreadedSimBackend::hand_over() {
  if (delivered_.empty()) return;
  // Stamped when handed over: the master cannot have had the frame earlier,
  // even when this thread was late for its simulated end of frame.
  const TimePoint handed = port::steady_now();
  {
    std::lock_guard lock(port_mutex_);
    for (const auto& [frame, end] : delivered_) to_port_.emplace_back(frame, std::max(end, handed));
  }
  delivered_.clear();
  port_woken_.notify_one();
}

void ThreadedSimBackend::run() {
  // Wake-ups at the simulated end of frame are timed waits: without this the
  // kernel's default timer slack (50 us) would add to every reception.
  (void)prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  std::vector<std::pair<can::CanFrame, TimePoint>> sending;
  std::vector<std::function<void()>> running;
  sending.reserve(64);
  std::unique_lock lock(world_mutex_);
  for (;;) {
    // Frames the port sent before the stop still reach the bus: the pass
    // that sees the stop sends them, then the thread ends.
    const bool last = stop_;
    sending.swap(to_world_);
    running.swap(posted_);
    lock.unlock();

    for (auto& fn : running) fn();
    running.clear();
    for (const auto& [frame, at] : sending) {
      // The world first catches up with the time the master sent at, so the
      // frame is queued on the bus at that time (or at once, if later).
      if (at > world_.now()) world_.run_until(at);
      world_.bus().send(handle_, frame, at);
    }
    sending.clear();
    world_.run_until(std::max(world_.now(), port::steady_now()));
    frames_.store(world_.bus().stats().transmitted, std::memory_order_relaxed);
    bits_.store(world_.bus().stats().bits, std::memory_order_relaxed);
    hand_over();

    const TimePoint next = world_.next_event();
    lock.lock();
    if (last) break;
    if (stop_ || !to_world_.empty() || !posted_.empty()) continue;
    if (next == kNever) {
      world_woken_.wait(lock);
    } else if (next > port::steady_now()) {
      world_woken_.wait_until(lock, port::to_steady(next));
    }
  }
}

void ThreadedSimBackend::wait(TimePoint deadline, port::FrameReceiver& receiver) {
  // Frames the world has not taken yet: wake it for them.
  bool queued = false;
  {
    std::lock_guard lock(world_mutex_);
    queued = !to_world_.empty();
  }
  if (queued) world_woken_.notify_one();
  {
    std::unique_lock lock(port_mutex_);
    auto ready = [&] { return wake_ || !to_port_.empty(); };
    if (deadline == kNever) {
      port_woken_.wait(lock, ready);
    } else {
      port_woken_.wait_until(lock, port::to_steady(deadline), ready);
    }
    wake_ = false;
    receiving_.swap(to_port_);
  }
  for (const auto& [frame, rx] : receiving_) {
    candump_.frame(frame, port::CandumpLog::wall_now());
    receiver.on_frame(frame, rx);
  }
  receiving_.clear();
}

void ThreadedSimBackend::wake() {
  {
    std::lock_guard lock(port_mutex_);
    wake_ = true;
  }
  port_woken_.notify_one();
}

port::BusCounters ThreadedSimBackend::counters() const {
  port::BusCounters c;
  c.state = port::BusState::kErrorActive;  // the simulated bus has no error confinement
  c.frames = frames_.load(std::memory_order_relaxed);
  c.bits = bits_.load(std::memory_order_relaxed);
  return c;
}

Duration ThreadedSimBackend::sim_thread_cpu_time() const {
  timespec ts{};
  if (sim_clock_ == -1 || clock_gettime(sim_clock_, &ts) != 0) return Duration::zero();
  return seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
}

}  // namespace dnbridge::sim
