#include "adapters/sim/world/sim_rack.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace dnbridge::sim {

SlaveOptions default_slave_options(devicenet::MacId mac) {
  SlaveOptions o;
  o.mac_switch = mac.value();
  o.stored_mac = mac.value();
  o.serial_number = 0x00010000u + mac.value();
  return o;
}

EdsSlaveOptions default_eds_slave_options(devicenet::MacId mac) {
  EdsSlaveOptions o;
  o.mac = mac.value();
  o.serial_number = 0x00010000u + mac.value();
  return o;
}

SimRack::SimRack(SimRackConfig config, LogSink* log)
    : config_(std::move(config)), log_(log), world_(config_.bus) {
  master_ =
      std::make_unique<SimMaster>(world_, [this](can::FrameSink& sink) -> devicenet::Scanner& {
        port_.emplace(config_.port, rack::PortNodes{config_.pumps, config_.devices}, sink,
                      log_ ? Logger(*log_, "master") : Logger(), config_.adjust_scan_list);
        return port_->scanner();
      });
  if (config_.create_devices) {
    for (const auto& p : config_.pumps) add_device(default_slave_options(p.node.mac), std::nullopt);
    for (const auto& d : config_.devices) {
      if (d.eds) add_eds_device(*d.eds, default_eds_slave_options(d.node.mac), std::nullopt);
    }
  }
}

SimSlave& SimRack::add_device(SlaveOptions options, std::optional<TimePoint> power_on) {
  const unsigned mac =
      options.mac_switch <= devicenet::MacId::kMax ? options.mac_switch : options.stored_mac;
  Logger log = log_ ? Logger(*log_, fmt::format("sim {}", mac)) : Logger();
  auto device = std::make_unique<SimSlave>(world_, std::move(options), power_on, std::move(log));
  auto& ref = *device;
  devices_[mac] = std::move(device);
  return ref;
}

SimSlave& SimRack::device(devicenet::MacId mac) {
  auto it = devices_.find(mac.value());
  if (it == devices_.end())
    throw std::out_of_range(fmt::format("no device at MAC {}", mac.value()));
  return *it->second;
}

SimEdsSlave& SimRack::add_eds_device(const profiles::eds::EdsFile& file, EdsSlaveOptions options,
                                     std::optional<TimePoint> power_on) {
  const unsigned mac = options.mac;
  Logger log = log_ ? Logger(*log_, fmt::format("sim {}", mac)) : Logger();
  auto device = std::make_unique<SimEdsSlave>(world_, file, options, power_on, std::move(log));
  auto& ref = *device;
  eds_devices_[mac] = std::move(device);
  return ref;
}

SimEdsSlave& SimRack::eds_device(devicenet::MacId mac) {
  auto it = eds_devices_.find(mac.value());
  if (it == eds_devices_.end())
    throw std::out_of_range(fmt::format("no EDS device at MAC {}", mac.value()));
  return *it->second;
}

void SimRack::start() {
  if (started_) return;
  started_ = true;
  for (auto& [mac, d] : devices_) {
    if (d->device().network_state() == Cdn127Slave::NetworkState::kOff) d->power_on(world_.now());
  }
  for (auto& [mac, d] : eds_devices_) {
    if (d->device().network_state() == Group2Slave::NetworkState::kOff) d->power_on(world_.now());
  }
  master_->scanner().start(world_.now());
}

bool SimRack::all_online() const {
  return std::all_of(port_->profiles().begin(), port_->profiles().end(),
                     [](const rack::ProfileNodes* nodes) {
                       for (std::size_t i = 0; i < nodes->size(); ++i) {
                         if (!nodes->view(i).online) return false;
                       }
                       return true;
                     });
}

}  // namespace dnbridge::sim
