#pragma once
// The system calls SocketCanBackend makes about its interface, behind one
// interface so that tests can make any of them fail on the Nth call (the
// way lely-core injects faults into libc) and drive the backend's clock.
// system_can_io() is the real thing: the calls themselves, nothing added.
//
// The backend's epoll set, eventfd and timerfd stay real descriptors; only
// arming the timer and waiting on the set go through here, so that a test's
// clock can decide when an armed timer fires.
#include <sys/epoll.h>

#include <cstdint>
#include <string>
#include <system_error>

#include "adapters/socketcan/can_socket.hpp"
#include "bridge/common/time.hpp"

struct can_berr_counter;
struct can_bittiming;

namespace dnbridge::socketcan {

class CanIo {
 public:
  virtual ~CanIo() = default;

  // The kernel and the interface (can_socket.hpp).
  virtual std::error_code can_support() = 0;
  virtual LinkState link_state(const std::string& interface) = 0;

  // The CAN_RAW socket (CanSocket's own calls).
  virtual Result<CanSocket> open(const std::string& interface, const SocketOptions& options) = 0;
  virtual Status write(CanSocket& socket, const can::CanFrame& frame) = 0;
  virtual Result<Received> read(CanSocket& socket) = 0;
  virtual std::error_code take_error(CanSocket& socket) = 0;

  // The controller behind the interface (libsocketcan; 0 on success, else
  // -1 with errno set). Only asked when has_controller() says there is one.
  virtual bool has_controller(const std::string& interface) = 0;
  virtual int get_state(const std::string& interface, int* state) = 0;
  virtual int get_berr_counter(const std::string& interface, can_berr_counter* counter) = 0;
  virtual int get_bittiming(const std::string& interface, can_bittiming* timing) = 0;
  virtual int get_restart_ms(const std::string& interface, std::uint32_t* restart_ms) = 0;
  virtual int do_restart(const std::string& interface) = 0;

  // The monotonic clock (CLOCK_MONOTONIC, the timerfd's), arming the timerfd
  // at an absolute time (kNever disarms), and epoll_wait().
  virtual TimePoint now() = 0;
  virtual void set_timer(int timer_fd, TimePoint at) = 0;
  virtual int wait(int epoll_fd, epoll_event* events, int max_events, int timeout_ms) = 0;
};

// The real system calls; one instance, stateless.
CanIo& system_can_io() noexcept;

}  // namespace dnbridge::socketcan
