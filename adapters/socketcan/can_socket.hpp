#pragma once
// A SocketCAN CAN_RAW socket and the descriptors around it, each with one
// owner (move-only; copying would close twice). Set-up follows can-utils'
// candump: socket, interface index by name, options, bind.
//
// Every call here returns the errno it met as a std::error_code in the system
// category; nothing throws. Reads and writes are non-blocking: EAGAIN means
// "nothing now", not a failure.
#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "bridge/can/can_frame.hpp"
#include "bridge/common/result.hpp"

namespace dnbridge::socketcan {

// One file descriptor, closed by its owner's destructor.
class FileDescriptor {
 public:
  FileDescriptor() noexcept = default;
  explicit FileDescriptor(int fd) noexcept : fd_(fd) {}
  ~FileDescriptor() { reset(); }
  FileDescriptor(FileDescriptor&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  FileDescriptor& operator=(FileDescriptor&& other) noexcept {
    if (this != &other) reset(std::exchange(other.fd_, -1));
    return *this;
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;

  int get() const noexcept { return fd_; }
  bool valid() const noexcept { return fd_ >= 0; }
  explicit operator bool() const noexcept { return valid(); }
  // Closes the descriptor held, if any, and takes `fd`.
  void reset(int fd = -1) noexcept;

 private:
  int fd_ = -1;
};

// errno as an error code.
std::error_code errno_code() noexcept;
std::error_code errno_code(int value) noexcept;
bool is(const std::error_code& e, int errno_value) noexcept;

// A CAN_RAW receive filter: a frame passes when (id & mask) == (filter.id & mask).
struct CanFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
};

struct SocketOptions {
  std::vector<CanFilter> filters;  // none: every data frame
  // CAN error frames (CAN_RAW_ERR_FILTER): controller state, bus-off,
  // restarts, transceiver, missing ACK, TX timeouts and protocol violations.
  bool error_frames = false;
  // Kernel receive timestamps (SO_TIMESTAMPING, software) on every frame.
  bool timestamps = true;
  // SO_RCVBUF in bytes; 0 keeps the system's default.
  int receive_buffer = 0;
  // The socket's own transmitted frames are received too (CAN_RAW_RECV_OWN_MSGS).
  bool receive_own = false;
};

// What one read returned.
struct Received {
  enum class Kind : std::uint8_t {
    kData,     // a classic data frame with an 11-bit identifier: `frame`
    kError,    // an error frame: `error_class` and `error_data`
    kForeign,  // extended identifier or remote request: not DeviceNet
  };
  Kind kind = Kind::kData;
  can::CanFrame frame;
  std::uint32_t error_class = 0;  // CAN_ERR_* class bits of the identifier
  std::array<std::uint8_t, 8> error_data{};
  std::uint32_t raw_id = 0;  // the identifier as read, flags included
  // Kernel receive time, CLOCK_REALTIME (what SO_TIMESTAMPING reports).
  std::optional<std::chrono::nanoseconds> kernel_time;
  // The socket's receive queue drop count (SO_RXQ_OVFL), when reported.
  std::optional<std::uint32_t> drops;
};

class CanSocket {
 public:
  CanSocket() noexcept = default;
  // Takes a descriptor already open (a test's socketpair end, for one).
  explicit CanSocket(FileDescriptor fd) noexcept : fd_(std::move(fd)) {}

  // Opens a non-blocking CAN_RAW socket bound to `interface`. Errors:
  // EAFNOSUPPORT (no CAN in this kernel), ENODEV (no such interface, or not
  // a CAN interface), and whatever socket options refuse.
  static Result<CanSocket> open(const std::string& interface,
                                const SocketOptions& options) noexcept;

  bool is_open() const noexcept { return fd_.valid(); }
  int fd() const noexcept { return fd_.get(); }
  void close() noexcept { fd_.reset(); }

  // One frame out. EAGAIN: the socket's send buffer is full; ENOBUFS: the
  // interface's transmit queue is full; ENETDOWN, ENODEV, ENXIO: the
  // interface is down or gone.
  Status write(const can::CanFrame& frame) noexcept;
  // One frame in; EAGAIN when none is waiting. ENETDOWN or ENODEV when the
  // interface went down or away (reported once by the kernel).
  Result<Received> read() noexcept;
  // The socket's pending error (SO_ERROR), which reading it clears.
  std::error_code take_error() noexcept;

 private:
  FileDescriptor fd_;
};

// What an interface name stands for now.
enum class LinkState : std::uint8_t {
  kAbsent,  // no interface of that name
  kNotCan,  // exists, but not a CAN interface
  kDown,    // a CAN interface, administratively down or without carrier
  kUp,
};
const char* to_string(LinkState s) noexcept;
LinkState link_state(const std::string& interface) noexcept;

// Whether this kernel has SocketCAN (socket(AF_CAN) works); the error if not.
std::error_code can_support() noexcept;

}  // namespace dnbridge::socketcan
