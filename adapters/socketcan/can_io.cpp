#include "adapters/socketcan/can_io.hpp"

#include <libsocketcan.h>
#include <sys/timerfd.h>

#include <algorithm>
#include <filesystem>

#include "adapters/port/steady_time.hpp"

namespace dnbridge::socketcan {
namespace {

class SystemCanIo final : public CanIo {
 public:
  std::error_code can_support() override { return socketcan::can_support(); }
  LinkState link_state(const std::string& interface) override {
    return socketcan::link_state(interface);
  }

  Result<CanSocket> open(const std::string& interface, const SocketOptions& options) override {
    return CanSocket::open(interface, options);
  }
  Status write(CanSocket& socket, const can::CanFrame& frame) override {
    return socket.write(frame);
  }
  Result<Received> read(CanSocket& socket) override { return socket.read(); }
  std::error_code take_error(CanSocket& socket) override { return socket.take_error(); }

  // A controller on hardware (USB, PCI, SPI) has a device behind it in sysfs;
  // virtual interfaces (vcan) do not, and have no state, counters or timing
  // to ask libsocketcan for (it would complain on standard error).
  bool has_controller(const std::string& interface) override {
    std::error_code ignored;
    return std::filesystem::exists("/sys/class/net/" + interface + "/device", ignored);
  }
  int get_state(const std::string& interface, int* state) override {
    return ::can_get_state(interface.c_str(), state);
  }
  int get_berr_counter(const std::string& interface, can_berr_counter* counter) override {
    return ::can_get_berr_counter(interface.c_str(), counter);
  }
  int get_bittiming(const std::string& interface, can_bittiming* timing) override {
    return ::can_get_bittiming(interface.c_str(), timing);
  }
  int get_restart_ms(const std::string& interface, std::uint32_t* restart_ms) override {
    return ::can_get_restart_ms(interface.c_str(), restart_ms);
  }
  int do_restart(const std::string& interface) override {
    return ::can_do_restart(interface.c_str());
  }

  // steady_clock is CLOCK_MONOTONIC, the timerfd's clock.
  TimePoint now() override { return port::steady_now(); }
  void set_timer(int timer_fd, TimePoint at) override {
    itimerspec spec{};
    if (at != kNever) {
      // An absolute time of zero disarms: the earliest real time is 1 ns.
      const auto ns = std::max<std::int64_t>(at.time_since_epoch().count(), 1);
      spec.it_value.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
      spec.it_value.tv_nsec = static_cast<long>(ns % 1'000'000'000);
    }
    (void)::timerfd_settime(timer_fd, TFD_TIMER_ABSTIME, &spec, nullptr);
  }
  int wait(int epoll_fd, epoll_event* events, int max_events, int timeout_ms) override {
    return ::epoll_wait(epoll_fd, events, max_events, timeout_ms);
  }
};

}  // namespace

CanIo& system_can_io() noexcept {
  static SystemCanIo io;
  return io;
}

}  // namespace dnbridge::socketcan
