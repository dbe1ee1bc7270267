#pragma once
// Simulated CDN127s, and devices driven by their EDS files, on a SocketCAN
// interface: each device is the sans-IO sim::Cdn127Slave or sim::EdsSlave of
// the in-process tests, unchanged, on a CAN_RAW socket of its own (so the devices hear each other
// as on a real bus: duplicate MAC checks included), driven by one epoll loop with a timerfd, the
// control input and SIGINT/SIGTERM.
#include <cstdio>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "adapters/sim/generic/eds_slave.hpp"
#include "adapters/sim/host/control.hpp"
#include "adapters/sim/host/device_config.hpp"
#include "adapters/socketcan/can_socket.hpp"
#include "bridge/common/log.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::sim::host {

// One device: its socket, its slave and its power.
class SocketDevice final : public can::FrameSink {
 public:
  // A CDN127, or a device driven by its EDS file.
  SocketDevice(DeviceSpec spec, Logger log);
  SocketDevice(const SocketDevice&) = delete;
  SocketDevice& operator=(const SocketDevice&) = delete;

  sim::Group2Slave& slave() { return *slave_; }
  const sim::Group2Slave& slave() const { return *slave_; }
  // The one of the two it is; the other is null.
  sim::Cdn127Slave* cdn127() { return cdn127_; }
  sim::EdsSlave* eds() { return eds_; }
  socketcan::CanSocket& socket() { return socket_; }
  devicenet::MacId mac() const { return mac_; }
  bool powered() const { return powered_; }

  void power_on(TimePoint now);
  void power_off();
  // Opens (again) on `interface`; the error if it cannot.
  std::error_code open(const std::string& interface);

  void send(const can::CanFrame& frame, TimePoint now) override;
  // Frames that waited for the interface, sent in order while it takes them.
  void flush(TimePoint now);
  TimePoint retry_at() const { return retry_at_; }
  bool lost_interface() const { return lost_; }
  void forget_interface() { lost_ = false; }

 private:
  devicenet::MacId mac_;
  Logger log_;
  socketcan::CanSocket socket_;
  std::unique_ptr<sim::Group2Slave> slave_;
  sim::Cdn127Slave* cdn127_ = nullptr;
  sim::EdsSlave* eds_ = nullptr;
  bool powered_ = false;
  bool lost_ = false;  // the interface went down under this device
  std::deque<can::CanFrame> queue_;
  TimePoint retry_at_ = kNever;
};

class SimHost {
 public:
  // Opens a socket per device on `interface` and powers every device on.
  // Throws std::system_error when the kernel has no SocketCAN or the
  // interface cannot be opened, std::invalid_argument for a repeated MAC.
  // Each device as sim::default_slave_options(mac) has it:
  SimHost(std::string interface, const std::vector<devicenet::MacId>& macs, LogSink& log);
  // Each device as `devices` describes it (a CDN127's MAC is that of its
  // switch, or its stored MAC when the switch is in the program position):
  SimHost(std::string interface, std::vector<DeviceSpec> devices, LogSink& log);
  ~SimHost();
  SimHost(const SimHost&) = delete;
  SimHost& operator=(const SimHost&) = delete;

  // Runs until `quit`, SIGINT or SIGTERM (blocked by the caller), or the end
  // of `control_fd` if `quit_at_end`. Replies go to `replies`.
  void run(int control_fd, bool quit_at_end, std::FILE* replies);

  // Executes one command; the reply line, without its newline.
  std::string execute(const ControlCommand& command, TimePoint now);
  TimePoint now() const;

 private:
  std::string status_line(SocketDevice& d, TimePoint now);
  std::string eds_status_line(SocketDevice& d);
  std::string set_input(SocketDevice& d, const ControlCommand& c, TimePoint now);
  // Reads what the device's socket holds, each frame handed over at the time it
  // is read.
  void on_socket(std::size_t index);
  void interface_lost(const std::error_code& why, TimePoint now);
  void try_reopen(TimePoint now);
  TimePoint next_deadline() const;

  std::string interface_;
  Logger log_;
  std::vector<std::unique_ptr<SocketDevice>> devices_;
  socketcan::FileDescriptor epoll_;
  socketcan::FileDescriptor timer_;
  socketcan::FileDescriptor signals_;
  bool interface_down_ = false;
  TimePoint reopen_at_ = kNever;
};

}  // namespace dnbridge::sim::host
