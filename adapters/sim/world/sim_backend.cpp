#include "adapters/sim/world/sim_backend.hpp"

#include <fmt/format.h>

#include <chrono>
#include <stdexcept>

#include "adapters/port/steady_time.hpp"
#include "adapters/sim/world/sim_rack.hpp"

namespace dnbridge::sim {

SimBackend::SimBackend(std::uint32_t bitrate, const std::vector<devicenet::MacId>& device_macs,
                       LogSink* log, const std::vector<EdsDeviceSpec>& eds_devices)
    : world_(BusConfig{bitrate}, port::steady_now()), handle_(world_.bus().attach(*this)) {
  const auto device_log = [log](devicenet::MacId mac) {
    return log ? Logger(*log, fmt::format("sim {}", mac.value())) : Logger();
  };
  for (auto mac : device_macs) {
    devices_[mac.value()] = std::make_unique<SimSlave>(world_, sim::default_slave_options(mac),
                                                       world_.now(), device_log(mac));
  }
  for (const auto& d : eds_devices) {
    eds_devices_[d.mac.value()] = std::make_unique<SimEdsSlave>(
        world_, *d.eds, default_eds_slave_options(d.mac), world_.now(), device_log(d.mac));
  }
}

SimBackend::~SimBackend() { (void)world_.bus().detach(handle_); }

TimePoint SimBackend::now() const { return port::steady_now(); }

SimSlave& SimBackend::device(devicenet::MacId mac) {
  auto it = devices_.find(mac.value());
  if (it == devices_.end())
    throw std::out_of_range(fmt::format("no simulated device {}", mac.value()));
  return *it->second;
}

SimEdsSlave& SimBackend::eds_device(devicenet::MacId mac) {
  auto it = eds_devices_.find(mac.value());
  if (it == eds_devices_.end())
    throw std::out_of_range(fmt::format("no simulated EDS device {}", mac.value()));
  return *it->second;
}

void SimBackend::MasterSink::send(const can::CanFrame& frame, TimePoint now) {
  owner_.candump_.frame(frame, port::CandumpLog::wall_now());
  owner_.world_.bus().sink(owner_.handle_).send(frame, now);
}

void SimBackend::on_frame(const can::CanFrame& frame, TimePoint rx_time) {
  received_.emplace_back(frame, rx_time);
}

void SimBackend::wait(TimePoint deadline, port::FrameReceiver& receiver) {
  for (;;) {
    // Bring the simulated world up to the real time; what it sends the
    // master is handed over with its simulated receive time.
    world_.run_until(std::max(world_.now(), now()));
    if (!received_.empty()) {
      while (!received_.empty()) {
        auto [frame, rx] = received_.front();
        received_.pop_front();
        candump_.frame(frame, port::CandumpLog::wall_now());
        receiver.on_frame(frame, rx);
      }
      world_.run_until(std::max(world_.now(), now()));
      return;
    }
    const TimePoint until = std::min(deadline, world_.next_event());
    std::unique_lock lock(mutex_);
    if (wake_) {
      wake_ = false;
      return;
    }
    if (now() >= deadline) return;
    woken_.wait_until(lock, port::to_steady(until), [&] { return wake_; });
    if (wake_) {
      wake_ = false;
      return;
    }
  }
}

void SimBackend::wake() {
  {
    std::lock_guard lock(mutex_);
    wake_ = true;
  }
  woken_.notify_one();
}

port::BusCounters SimBackend::counters() const {
  port::BusCounters c;
  c.state = port::BusState::kErrorActive;  // the simulated bus has no error confinement
  c.frames = world_.bus().stats().transmitted;
  c.bits = world_.bus().stats().bits;
  return c;
}

}  // namespace dnbridge::sim
