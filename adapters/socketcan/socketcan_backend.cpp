#include "adapters/socketcan/socketcan_backend.hpp"

#include <fmt/format.h>
#include <linux/can/netlink.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <stdexcept>
#include <system_error>

#include "bridge/can/can_timing.hpp"
#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::socketcan {
namespace {

using port::BusState;

// epoll tokens.
constexpr std::uint32_t kSocketToken = 1;
constexpr std::uint32_t kWakeToken = 2;
constexpr std::uint32_t kTimerToken = 3;

// Frames read per wait() at most, so that timers are never starved by a
// flooded bus.
constexpr int kReadBatch = 64;
constexpr Duration kFirstBackoff = milliseconds(1);
constexpr Duration kMaxBackoff = milliseconds(32);

std::chrono::nanoseconds wall_now() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::system_clock::now().time_since_epoch());
}

bool interface_gone(const std::error_code& e) {
  return is(e, ENETDOWN) || is(e, ENODEV) || is(e, ENXIO) || is(e, ENETUNREACH);
}

}  // namespace

const char* to_string(BusOffRecovery r) noexcept {
  switch (r) {
    case BusOffRecovery::kInterface:
      return "interface";
    case BusOffRecovery::kRestart:
      return "restart";
    case BusOffRecovery::kReport:
      return "report";
  }
  return "?";
}

std::vector<CanFilter> master_filters() {
  using devicenet::Group1Message;
  using devicenet::Group2Message;
  // Group 1: 0 MMMM SSSSSS (message, source MAC); Group 2: 10 SSSSSS MMM
  // (MAC, message); Group 4: 11111 MMMMMM (bridge/PROTOCOL.md §1).
  const auto g1 = [](Group1Message m) {
    return CanFilter{static_cast<std::uint32_t>(m) << 6, 0x7C0};
  };
  const auto g2 = [](Group2Message m) {
    return CanFilter{0x400u | static_cast<std::uint32_t>(m), 0x607};
  };
  return {g1(Group1Message::kSlavePollResponse),      g1(Group1Message::kSlaveCosCyclic),
          g1(Group1Message::kSlaveBitStrobeResponse), g2(Group2Message::kSlaveExplicitResponse),
          g2(Group2Message::kDuplicateMacCheck),      CanFilter{0x7C0, 0x7C0}};
}

std::optional<BusState> SocketCanBackend::state_from_netlink() {
  if (!io_->has_controller(options_.interface)) return std::nullopt;
  int state = 0;
  if (io_->get_state(options_.interface, &state) != 0) return std::nullopt;
  switch (state) {
    case CAN_STATE_ERROR_ACTIVE:
      return BusState::kErrorActive;
    case CAN_STATE_ERROR_WARNING:
      return BusState::kErrorWarning;
    case CAN_STATE_ERROR_PASSIVE:
      return BusState::kErrorPassive;
    case CAN_STATE_BUS_OFF:
      return BusState::kBusOff;
    default:
      return BusState::kUnknown;  // stopped, sleeping
  }
}

SocketCanBackend::SocketCanBackend(SocketCanOptions options, Logger log)
    : SocketCanBackend(std::move(options), std::move(log), system_can_io()) {}

SocketCanBackend::SocketCanBackend(SocketCanOptions options, Logger log, CanIo& io)
    : options_(std::move(options)), log_(std::move(log)), io_(&io) {
  if (io_->link_state(options_.interface) == LinkState::kNotCan) {
    throw std::runtime_error(
        fmt::format("interface \"{}\" is not a CAN interface", options_.interface));
  }
  epoll_.reset(::epoll_create1(EPOLL_CLOEXEC));
  wake_fd_.reset(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  timer_fd_.reset(::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC));
  if (!epoll_ || !wake_fd_ || !timer_fd_) {
    throw std::system_error(errno_code(), "creating the port's epoll, eventfd and timerfd");
  }
  for (auto [fd, token] : {std::pair{wake_fd_.get(), kWakeToken}, {timer_fd_.get(), kTimerToken}}) {
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u32 = token;
    if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, fd, &ev) < 0) {
      throw std::system_error(errno_code(), "epoll_ctl");
    }
  }
  bus_.state = BusState::kDown;
  problem_ = fmt::format("{}: not opened yet", options_.interface);
  try_open(now());
  if (!socket_.is_open())
    log_.warn("{}; checked again every {} ms", problem_,
              std::chrono::duration_cast<milliseconds>(options_.reopen_period).count());
}

SocketCanBackend::~SocketCanBackend() = default;

TimePoint SocketCanBackend::now() const { return io_->now(); }

void SocketCanBackend::wake() {
  const std::uint64_t one = 1;
  // EAGAIN only when the counter is saturated: a wake-up is pending anyway.
  (void)!::write(wake_fd_.get(), &one, sizeof one);
}

// --- opening and losing the interface ----------------------------------------

void SocketCanBackend::try_open(TimePoint now) {
  reopen_at_ = now + options_.reopen_period;
  const LinkState link = io_->link_state(options_.interface);
  if (link != LinkState::kUp) {
    // A kernel without SocketCAN has no CAN interface either: say why.
    if (auto e = io_->can_support()) {
      problem_ = fmt::format("interface {}: this kernel has no SocketCAN (socket(AF_CAN): {})",
                             options_.interface, e.message());
    } else {
      problem_ = fmt::format("interface {} {}", options_.interface, to_string(link));
    }
    return;
  }
  SocketOptions so;
  so.filters = options_.filters;
  so.error_frames = true;
  so.timestamps = true;
  so.receive_buffer = options_.receive_buffer;
  auto opened = io_->open(options_.interface, so);
  if (!opened) {
    problem_ = fmt::format("interface {}: {}", options_.interface, opened.error().message());
    return;
  }
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.u32 = kSocketToken;
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, opened->fd(), &ev) < 0) {
    problem_ = fmt::format("interface {}: epoll: {}", options_.interface, errno_code().message());
    return;
  }
  socket_ = std::move(*opened);
  writable_wanted_ = false;
  reopen_at_ = kNever;
  last_drops_ = 0;
  problem_.clear();
  // A real controller reports its state and counters over netlink; a
  // virtual one (vcan) has none, and stays "unknown".
  set_bus_state(state_from_netlink().value_or(BusState::kUnknown));
  can_berr_counter berr{};
  if (!io_->has_controller(options_.interface)) {
    // Nothing more to ask a virtual interface.
  } else if (io_->get_berr_counter(options_.interface, &berr) == 0) {
    bus_.tx_errors = berr.txerr;
    bus_.rx_errors = berr.rxerr;
  }
  can_bittiming timing{};
  if (io_->has_controller(options_.interface) &&
      io_->get_bittiming(options_.interface, &timing) == 0 && timing.bitrate != 0 &&
      timing.bitrate != options_.bitrate) {
    log_.warn("interface {} runs at {} bit/s, the configuration says {}", options_.interface,
              timing.bitrate, options_.bitrate);
  }
  if (bus_.state == BusState::kBusOff && options_.bus_off == BusOffRecovery::kRestart) {
    restart_at_ = now + options_.restart_delay;
  }
  if (stats_.reopens++ == 0) {
    log_.info("interface {} open (bus {})", options_.interface, to_string(bus_.state));
  } else {
    log_.warn("interface {} is back (bus {}): scanning resumes", options_.interface,
              to_string(bus_.state));
  }
}

void SocketCanBackend::go_down(const std::string& why, TimePoint now) {
  if (socket_.is_open()) {
    (void)::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, socket_.fd(), nullptr);
    socket_.close();
  }
  drop_queue("the interface went down");
  set_bus_state(BusState::kDown);
  problem_ = fmt::format("interface {}: {}", options_.interface, why);
  log_.error("{}; checked again every {} ms", problem_,
             std::chrono::duration_cast<milliseconds>(options_.reopen_period).count());
  reopen_at_ = now + options_.reopen_period;
  restart_at_ = kNever;
}

void SocketCanBackend::set_bus_state(BusState state) {
  if (port::bus_lost(state) && !port::bus_lost(bus_.state)) ++bus_.losses;
  bus_.state = state;
}

// --- the wait --------------------------------------------------------------

TimePoint SocketCanBackend::own_deadline() const {
  return std::min({transmit_retry_at_, reopen_at_, restart_at_});
}

void SocketCanBackend::arm_timer(TimePoint at) {
  if (at == armed_) return;
  armed_ = at;
  io_->set_timer(timer_fd_.get(), at);
}

void SocketCanBackend::run_timers(TimePoint now) {
  if (!socket_.is_open() && now >= reopen_at_) try_open(now);
  if (socket_.is_open() && now >= transmit_retry_at_) {
    transmit_retry_at_ = kNever;
    flush(now);
  }
  if (now >= restart_at_) {
    restart_at_ = kNever;
    if (bus_.state == BusState::kBusOff) {
      ++stats_.restarts;
      if (io_->do_restart(options_.interface) == 0) {
        log_.warn("bus-off: interface {} restarted", options_.interface);
      } else {
        // Not permitted (CAP_NET_ADMIN) or not a controller that restarts:
        // tried again, as the policy says the bridge restarts it.
        log_.error("bus-off: restarting interface {} failed: {}", options_.interface,
                   errno_code().message());
        restart_at_ = now + std::max<Duration>(options_.restart_delay, seconds(1));
      }
    }
  }
}

void SocketCanBackend::wait(TimePoint deadline, port::FrameReceiver& receiver) {
  bool delivered = false;
  for (;;) {
    TimePoint t = now();
    run_timers(t);
    // A deadline already past still gets one look at what is waiting, so
    // that received frames are never starved by a busy caller.
    const bool due = t >= deadline;
    if (!due) arm_timer(std::min(deadline, own_deadline()));

    epoll_event events[4];
    const int n = io_->wait(epoll_.get(), events, 4, due ? 0 : -1);
    if (n < 0) {
      if (errno == EINTR) continue;
      log_.error("epoll_wait: {}", errno_code().message());
      return;
    }
    t = now();
    bool woken = false;
    for (int i = 0; i < n; ++i) {
      const auto& ev = events[i];
      if (ev.data.u32 == kWakeToken) {
        std::uint64_t count = 0;
        (void)!::read(wake_fd_.get(), &count, sizeof count);
        woken = true;
      } else if (ev.data.u32 == kTimerToken) {
        std::uint64_t expiries = 0;
        (void)!::read(timer_fd_.get(), &expiries, sizeof expiries);
        armed_ = kNever;  // fired: disarmed
      } else if (ev.data.u32 == kSocketToken && socket_.is_open()) {
        if (ev.events & (EPOLLIN | EPOLLERR | EPOLLHUP)) receive(receiver, delivered, t);
        if (socket_.is_open() && (ev.events & EPOLLOUT)) {
          want_writable(false);
          flush(t);
        }
      }
    }
    if (delivered || woken || due) return;
  }
}

// --- receiving ---------------------------------------------------------------

void SocketCanBackend::receive(port::FrameReceiver& receiver, bool& delivered, TimePoint now) {
  // The kernel stamps frames on the wall clock: moved onto the monotonic
  // clock by the offset between the two, read once per batch.
  const auto wall = wall_now();
  for (int i = 0; i < kReadBatch && socket_.is_open(); ++i) {
    auto r = io_->read(socket_);
    if (!r) {
      if (is(r.error(), EAGAIN) || is(r.error(), EWOULDBLOCK)) return;
      if (interface_gone(r.error())) {
        go_down(r.error().message(), now);
        return;
      }
      error_log_limit_.warn(log_, now, "reading from {}: {}", options_.interface,
                            r.error().message());
      // A pending socket error is cleared by reading it.
      if (auto e = io_->take_error(socket_); e && interface_gone(e)) go_down(e.message(), now);
      return;
    }
    if (r->drops && *r->drops != last_drops_) {
      const std::uint32_t lost = *r->drops - last_drops_;
      stats_.receive_overruns += lost;
      last_drops_ = *r->drops;
      log_.warn("{}: the socket's receive queue dropped {} frame(s)", options_.interface, lost);
    }
    TimePoint rx = now;
    if (r->kernel_time) {
      const Duration age = std::chrono::duration_cast<Duration>(wall - *r->kernel_time);
      if (age > Duration::zero()) rx = now - age;
    }
    switch (r->kind) {
      case Received::Kind::kData:
        ++stats_.received;
        ++bus_.frames;
        bus_.bits += can::frame_bits(r->frame);
        candump_.frame(r->frame, r->kernel_time.value_or(wall));
        receiver.on_frame(r->frame, rx);
        delivered = true;
        break;
      case Received::Kind::kError:
        ++stats_.error_frames;
        candump_.error_frame(r->raw_id, r->error_data, r->kernel_time.value_or(wall));
        on_error_frame(*r, rx);
        break;
      case Received::Kind::kForeign:
        ++stats_.foreign_frames;
        break;
    }
  }
}

void SocketCanBackend::on_error_frame(const Received& r, TimePoint now) {
  const ErrorFrameReport report = decode_error_frame(r.error_class, r.error_data);
  if (report.tx_errors) bus_.tx_errors = *report.tx_errors;
  if (report.rx_errors) bus_.rx_errors = *report.rx_errors;
  const BusState before = bus_.state;
  if (report.state) set_bus_state(*report.state);

  if (bus_.state != before) {
    const LogLevel level = bus_.state == BusState::kErrorActive ? LogLevel::kInfo
                           : bus_.state == BusState::kBusOff    ? LogLevel::kError
                                                                : LogLevel::kWarn;
    log_.log(level, "bus {} -> {}: {}", to_string(before), to_string(bus_.state), describe(report));
  } else {
    error_log_limit_.warn(log_, now, "error frame: {}", describe(report));
  }

  if (report.bus_off) {
    drop_queue("bus-off");
    switch (options_.bus_off) {
      case BusOffRecovery::kInterface: {
        std::uint32_t restart_ms = 0;
        if (io_->has_controller(options_.interface) &&
            io_->get_restart_ms(options_.interface, &restart_ms) == 0 && restart_ms == 0) {
          log_.error(
              "bus-off, and interface {} has no restart-ms: it stays off until restarted (ip link "
              "set {} type can restart-ms 100)",
              options_.interface, options_.interface);
        }
        break;
      }
      case BusOffRecovery::kRestart:
        restart_at_ = now + options_.restart_delay;
        break;
      case BusOffRecovery::kReport:
        log_.error(
            "bus-off: interface {} stays off until restarted (ip link set {} type can restart)",
            options_.interface, options_.interface);
        break;
    }
    problem_ = fmt::format("interface {}: bus-off", options_.interface);
  }
  if (report.restarted) {
    restart_at_ = kNever;
    problem_.clear();
  }
}

// --- transmitting ------------------------------------------------------------

void SocketCanBackend::transmit(const can::CanFrame& frame, TimePoint now) {
  if (!socket_.is_open() || bus_.state == BusState::kBusOff) {
    ++stats_.transmit_dropped;
    return;
  }
  // Behind frames already waiting: never overtake them.
  if (!queue_.empty()) {
    enqueue(frame, now);
    return;
  }
  if (!try_write(frame, now) && socket_.is_open()) {
    ++stats_.transmit_deferred;
    queue_.push_back(frame);
  }
}

bool SocketCanBackend::try_write(const can::CanFrame& frame, TimePoint now) {
  auto s = io_->write(socket_, frame);
  if (s) {
    ++stats_.transmitted;
    ++bus_.frames;
    bus_.bits += can::frame_bits(frame);
    transmit_backoff_ = Duration::zero();
    candump_.frame(frame, wall_now());
    return true;
  }
  const auto& e = s.error();
  if (is(e, EAGAIN) || is(e, EWOULDBLOCK)) {
    // The socket's send buffer is full: epoll says when it has room.
    want_writable(true);
    return false;
  }
  if (is(e, ENOBUFS)) {
    // The interface's queue is full; epoll does not report when it drains.
    transmit_backoff_ = transmit_backoff_ == Duration::zero()
                            ? kFirstBackoff
                            : std::min(2 * transmit_backoff_, kMaxBackoff);
    transmit_retry_at_ = now + transmit_backoff_;
    return false;
  }
  if (interface_gone(e)) {
    go_down(e.message(), now);
    return false;
  }
  // Refused for this frame alone (EINVAL, EMSGSIZE, ...): dropped.
  ++stats_.transmit_dropped;
  transmit_log_limit_.warn(log_, now, "frame 0x{:03X} not sent on {}: {}", frame.id,
                           options_.interface, e.message());
  return true;  // nothing to retry
}

void SocketCanBackend::enqueue(const can::CanFrame& frame, TimePoint now) {
  if (queue_.size() >= options_.transmit_queue_limit) {
    ++stats_.transmit_dropped;
    transmit_log_limit_.warn(log_, now,
                             "{}: {} frames wait for the interface; frame 0x{:03X} dropped",
                             options_.interface, queue_.size(), frame.id);
    return;
  }
  ++stats_.transmit_deferred;
  queue_.push_back(frame);
}

void SocketCanBackend::flush(TimePoint now) {
  while (!queue_.empty() && socket_.is_open()) {
    if (!try_write(queue_.front(), now)) return;
    if (!queue_.empty()) queue_.pop_front();
  }
  want_writable(false);
}

void SocketCanBackend::drop_queue(const char* why) {
  if (!queue_.empty()) {
    log_.warn("{} frame(s) waiting for {} dropped: {}", queue_.size(), options_.interface, why);
    stats_.transmit_dropped += queue_.size();
    queue_.clear();
  }
  transmit_retry_at_ = kNever;
  transmit_backoff_ = Duration::zero();
  want_writable(false);
}

void SocketCanBackend::want_writable(bool on) {
  if (on == writable_wanted_ || !socket_.is_open()) {
    if (!socket_.is_open()) writable_wanted_ = false;
    return;
  }
  epoll_event ev{};
  ev.events = EPOLLIN | (on ? EPOLLOUT : 0u);
  ev.data.u32 = kSocketToken;
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_MOD, socket_.fd(), &ev) == 0) writable_wanted_ = on;
}

}  // namespace dnbridge::socketcan
