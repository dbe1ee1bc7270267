#include "adapters/socketcan/can_socket.hpp"

// <net/if.h> before any <linux/...> header: glibc then tells the kernel's
// headers which interface definitions it already has.
#include <net/if.h>
// clang-format off
#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/errqueue.h>
#include <linux/if_arp.h>
#include <linux/net_tstamp.h>
// clang-format on
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace dnbridge::socketcan {

void FileDescriptor::reset(int fd) noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
}

std::error_code errno_code() noexcept { return errno_code(errno); }
std::error_code errno_code(int value) noexcept { return {value, std::system_category()}; }
bool is(const std::error_code& e, int errno_value) noexcept {
  return e.category() == std::system_category() && e.value() == errno_value;
}

namespace {

template <class T>
Status set_option(int fd, int level, int name, const T& value) noexcept {
  if (::setsockopt(fd, level, name, &value, sizeof value) < 0) return errno_code();
  return {};
}

}  // namespace

Result<CanSocket> CanSocket::open(const std::string& interface,
                                  const SocketOptions& options) noexcept {
  if (interface.empty() || interface.size() >= IFNAMSIZ) return errno_code(ENODEV);
  FileDescriptor fd(::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW));
  if (!fd) return errno_code();

  const unsigned index = ::if_nametoindex(interface.c_str());
  if (index == 0) return errno_code(ENODEV);

  // Receive filters: none given means every data frame (the kernel's default
  // filter); an explicit list replaces it.
  if (!options.filters.empty()) {
    std::vector<can_filter> filters;
    filters.reserve(options.filters.size());
    for (const auto& f : options.filters) {
      // CAN_EFF_FLAG and CAN_RTR_FLAG in the mask: only standard data frames
      // pass, as DeviceNet uses no other kind.
      filters.push_back(can_filter{f.id, f.mask | CAN_EFF_FLAG | CAN_RTR_FLAG});
    }
    if (::setsockopt(fd.get(), SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                     static_cast<socklen_t>(filters.size() * sizeof(can_filter))) < 0) {
      return errno_code();
    }
  }
  if (options.error_frames) {
    // Bus errors (CAN_ERR_BUSERROR) and lost arbitration are left out: they
    // can flood, and bus state comes from the controller classes.
    const can_err_mask_t mask = CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_PROT | CAN_ERR_TRX |
                                CAN_ERR_ACK | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;
    if (auto s = set_option(fd.get(), SOL_CAN_RAW, CAN_RAW_ERR_FILTER, mask); !s) return s.error();
  }
  if (options.receive_own) {
    const int on = 1;
    if (auto s = set_option(fd.get(), SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, on); !s) return s.error();
  }
  if (options.receive_buffer > 0) {
    // SO_RCVBUFFORCE passes the system's limit but needs CAP_NET_ADMIN.
    if (!set_option(fd.get(), SOL_SOCKET, SO_RCVBUFFORCE, options.receive_buffer)) {
      if (auto s = set_option(fd.get(), SOL_SOCKET, SO_RCVBUF, options.receive_buffer); !s) {
        return s.error();
      }
    }
  }
  if (options.timestamps) {
    const int flags = SOF_TIMESTAMPING_RX_SOFTWARE | SOF_TIMESTAMPING_SOFTWARE;
    if (!set_option(fd.get(), SOL_SOCKET, SO_TIMESTAMPING, flags)) {
      // Older kernels: the microsecond stamp.
      const int on = 1;
      if (auto s = set_option(fd.get(), SOL_SOCKET, SO_TIMESTAMP, on); !s) return s.error();
    }
  }
  {
    // The receive queue's drop count comes with every frame: overruns are
    // seen, not guessed.
    const int on = 1;
    (void)set_option(fd.get(), SOL_SOCKET, SO_RXQ_OVFL, on);
  }

  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(index);
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) < 0) {
    return errno_code();
  }
  return CanSocket(std::move(fd));
}

Status CanSocket::write(const can::CanFrame& frame) noexcept {
  if (!fd_) return errno_code(EBADF);
  can_frame out{};
  out.can_id = frame.id & CAN_SFF_MASK;
  out.len = frame.len;
  std::memcpy(out.data, frame.data.data(), frame.len);
  const ssize_t n = ::write(fd_.get(), &out, sizeof out);
  if (n < 0) return errno_code();
  if (static_cast<std::size_t>(n) != sizeof out) return errno_code(EIO);
  return {};
}

Result<Received> CanSocket::read() noexcept {
  if (!fd_) return errno_code(EBADF);
  can_frame in{};
  iovec iov{&in, sizeof in};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(scm_timestamping)) + CMSG_SPACE(sizeof(timeval)) +
                                CMSG_SPACE(sizeof(std::uint32_t))];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  const ssize_t n = ::recvmsg(fd_.get(), &msg, MSG_DONTWAIT);
  if (n < 0) return errno_code();
  if (static_cast<std::size_t>(n) != sizeof in) return errno_code(EPROTO);  // not a classic frame

  Received r;
  r.raw_id = in.can_id;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SO_TIMESTAMPING) {
      scm_timestamping ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      if (ts.ts[0].tv_sec || ts.ts[0].tv_nsec) {
        r.kernel_time =
            std::chrono::seconds(ts.ts[0].tv_sec) + std::chrono::nanoseconds(ts.ts[0].tv_nsec);
      }
    } else if (c->cmsg_type == SO_TIMESTAMP) {
      timeval tv{};
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      r.kernel_time = std::chrono::seconds(tv.tv_sec) + std::chrono::microseconds(tv.tv_usec);
    } else if (c->cmsg_type == SO_RXQ_OVFL) {
      std::uint32_t drops = 0;
      std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
      r.drops = drops;
    }
  }

  const std::uint8_t len = in.len > can::kMaxDataLength ? can::kMaxDataLength : in.len;
  if (in.can_id & CAN_ERR_FLAG) {
    r.kind = Received::Kind::kError;
    r.error_class = in.can_id & CAN_ERR_MASK;
    std::memcpy(r.error_data.data(), in.data, sizeof in.data);
  } else if (in.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG)) {
    r.kind = Received::Kind::kForeign;
  } else {
    r.kind = Received::Kind::kData;
    r.frame.id = in.can_id & CAN_SFF_MASK;
    r.frame.len = len;
    std::memcpy(r.frame.data.data(), in.data, len);
  }
  return r;
}

std::error_code CanSocket::take_error() noexcept {
  int error = 0;
  socklen_t size = sizeof error;
  if (::getsockopt(fd_.get(), SOL_SOCKET, SO_ERROR, &error, &size) < 0) return errno_code();
  return error ? errno_code(error) : std::error_code();
}

const char* to_string(LinkState s) noexcept {
  switch (s) {
    case LinkState::kAbsent:
      return "absent";
    case LinkState::kNotCan:
      return "not a CAN interface";
    case LinkState::kDown:
      return "down";
    case LinkState::kUp:
      return "up";
  }
  return "?";
}

LinkState link_state(const std::string& interface) noexcept {
  if (interface.empty() || interface.size() >= IFNAMSIZ) return LinkState::kAbsent;
  // Interface ioctls work on any socket; a UNIX one exists on every kernel.
  FileDescriptor fd(::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0));
  if (!fd) return LinkState::kAbsent;
  ifreq req{};
  std::memcpy(req.ifr_name, interface.data(), interface.size());
  if (::ioctl(fd.get(), SIOCGIFHWADDR, &req) < 0) return LinkState::kAbsent;
  if (req.ifr_hwaddr.sa_family != ARPHRD_CAN) return LinkState::kNotCan;
  if (::ioctl(fd.get(), SIOCGIFFLAGS, &req) < 0) return LinkState::kAbsent;
  // IFF_RUNNING: a CAN controller that is up but stopped (e.g. bus-off
  // without restart) has no carrier.
  const int flags = req.ifr_flags;
  if (!(flags & IFF_UP) || !(flags & IFF_RUNNING)) return LinkState::kDown;
  return LinkState::kUp;
}

std::error_code can_support() noexcept {
  FileDescriptor fd(::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW));
  return fd ? std::error_code() : errno_code();
}

}  // namespace dnbridge::socketcan
