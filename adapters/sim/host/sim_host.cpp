#include "adapters/sim/host/sim_host.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <signal.h>
#include <sys/epoll.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <set>
#include <stdexcept>
#include <system_error>

#include "adapters/port/steady_time.hpp"
#include "adapters/sim/host/device_config.hpp"
#include "adapters/sim/world/sim_rack.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"

namespace dnbridge::sim::host {
namespace {

using socketcan::errno_code;
using socketcan::is;

constexpr std::uint64_t kControlToken = 1000;
constexpr std::uint64_t kTimerToken = 1001;
constexpr std::uint64_t kSignalToken = 1002;
constexpr Duration kReopenPeriod = milliseconds(500);
constexpr Duration kRetry = milliseconds(2);
constexpr std::size_t kQueueLimit = 64;

bool interface_gone(const std::error_code& e) {
  return is(e, ENETDOWN) || is(e, ENODEV) || is(e, ENXIO);
}

const char* on_off(bool b) { return b ? "on" : "off"; }

// "none", or the faults that stand: "major-recoverable,minor-recoverable".
std::string fault_list(const sim::IdentityFaults& f) {
  std::string out;
  auto add = [&out](bool on, const char* name) {
    if (!on) return;
    if (!out.empty()) out += ',';
    out += name;
  };
  add(f.major_unrecoverable, "major-unrecoverable");
  add(f.major_recoverable, "major-recoverable");
  add(f.minor_unrecoverable, "minor-unrecoverable");
  add(f.minor_recoverable, "minor-recoverable");
  return out.empty() ? "none" : out;
}

bool& fault_flag(sim::IdentityFaults& f, Fault which) {
  switch (which) {
    case Fault::kMinorRecoverable:
      return f.minor_recoverable;
    case Fault::kMinorUnrecoverable:
      return f.minor_unrecoverable;
    case Fault::kMajorRecoverable:
      return f.major_recoverable;
    case Fault::kMajorUnrecoverable:
      break;
  }
  return f.major_unrecoverable;
}

}  // namespace

// --- one device ------------------------------------------------------------

namespace {

devicenet::MacId device_mac(const sim::SlaveOptions& o) {
  return devicenet::MacId::from_bits(o.mac_switch <= devicenet::MacId::kMax ? o.mac_switch
                                                                            : o.stored_mac);
}

devicenet::MacId device_mac(const DeviceSpec& d) {
  return d.eds ? devicenet::MacId::from_bits(d.eds_options.mac) : device_mac(d.cdn127);
}

}  // namespace

SocketDevice::SocketDevice(DeviceSpec spec, Logger log) : mac_(device_mac(spec)), log_(log) {
  if (spec.eds) {
    auto slave =
        std::make_unique<sim::EdsSlave>(*this, *spec.eds->file, spec.eds_options, std::move(log));
    eds_ = slave.get();
    slave_ = std::move(slave);
  } else {
    auto slave = std::make_unique<sim::Cdn127Slave>(*this, std::move(spec.cdn127), std::move(log));
    cdn127_ = slave.get();
    slave_ = std::move(slave);
  }
}

std::error_code SocketDevice::open(const std::string& interface) {
  socketcan::SocketOptions o;
  o.timestamps = false;  // the slave takes the time it is handed the frame
  auto s = socketcan::CanSocket::open(interface, o);
  if (!s) return s.error();
  socket_ = std::move(*s);
  lost_ = false;
  return {};
}

void SocketDevice::power_on(TimePoint now) {
  powered_ = true;
  queue_.clear();
  retry_at_ = kNever;
  slave_->power_on(now);
}

void SocketDevice::power_off() {
  powered_ = false;
  queue_.clear();
  retry_at_ = kNever;
}

void SocketDevice::send(const can::CanFrame& frame, TimePoint now) {
  if (!powered_ || !socket_.is_open()) return;
  if (!queue_.empty()) {
    if (queue_.size() < kQueueLimit) queue_.push_back(frame);
    return;
  }
  auto s = socket_.write(frame);
  if (s) return;
  if (is(s.error(), EAGAIN) || is(s.error(), ENOBUFS)) {
    // A device on a busy bus waits its turn, in order.
    queue_.push_back(frame);
    retry_at_ = now + kRetry;
  } else if (interface_gone(s.error())) {
    lost_ = true;
  } else {
    log_.warn("frame 0x{:03X} not sent: {}", frame.id, s.error().message());
  }
}

void SocketDevice::flush(TimePoint now) {
  retry_at_ = kNever;
  while (!queue_.empty() && socket_.is_open()) {
    auto s = socket_.write(queue_.front());
    if (!s) {
      if (is(s.error(), EAGAIN) || is(s.error(), ENOBUFS)) {
        retry_at_ = now + kRetry;
        return;
      }
      if (interface_gone(s.error())) lost_ = true;
      queue_.clear();
      return;
    }
    queue_.pop_front();
  }
}

// --- the host ----------------------------------------------------------------

namespace {

std::vector<DeviceSpec> factory_options(const std::vector<devicenet::MacId>& macs) {
  std::vector<DeviceSpec> out(macs.size());
  for (std::size_t i = 0; i < macs.size(); ++i) out[i].cdn127 = sim::default_slave_options(macs[i]);
  return out;
}

std::string describe(const DeviceSpec& d) {
  if (!d.eds) return describe_readings(d.cdn127);
  return fmt::format("\"{}\" driven by {}", d.eds->file->device.product_name, d.eds->path);
}

}  // namespace

SimHost::SimHost(std::string interface, const std::vector<devicenet::MacId>& macs, LogSink& log)
    : SimHost(std::move(interface), factory_options(macs), log) {}

SimHost::SimHost(std::string interface, std::vector<DeviceSpec> devices, LogSink& log)
    : interface_(std::move(interface)), log_(log, "cdn127-sim") {
  if (auto e = socketcan::can_support()) {
    throw std::system_error(e, "this kernel has no SocketCAN (socket(AF_CAN))");
  }
  std::vector<devicenet::MacId> macs;
  std::set<unsigned> seen;
  for (const auto& o : devices) {
    macs.push_back(device_mac(o));
    if (!seen.insert(macs.back().value()).second) {
      throw std::invalid_argument(fmt::format("MAC {} given twice", macs.back().value()));
    }
  }
  epoll_.reset(::epoll_create1(EPOLL_CLOEXEC));
  timer_.reset(::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC));
  if (!epoll_ || !timer_) throw std::system_error(errno_code(), "epoll or timerfd");

  const TimePoint t = now();
  for (std::size_t i = 0; i < macs.size(); ++i) {
    log_.info("device {}: {}", macs[i].value(), describe(devices[i]));
    auto d = std::make_unique<SocketDevice>(std::move(devices[i]),
                                            Logger(log, fmt::format("sim {}", macs[i].value())));
    if (auto e = d->open(interface_)) {
      throw std::system_error(
          e, fmt::format("opening {} for the device at MAC {}", interface_, macs[i].value()));
    }
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = i;
    if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, d->socket().fd(), &ev) < 0) {
      throw std::system_error(errno_code(), "epoll_ctl");
    }
    devices_.push_back(std::move(d));
  }
  for (auto& d : devices_) d->power_on(t);
  log_.info("{} device(s) powered on {}", devices_.size(), interface_);
}

SimHost::~SimHost() = default;

TimePoint SimHost::now() const { return port::steady_now(); }

TimePoint SimHost::next_deadline() const {
  TimePoint t = reopen_at_;
  for (const auto& d : devices_) {
    if (!d->powered()) continue;
    t = std::min({t, d->slave().next_deadline(), d->retry_at()});
  }
  return t;
}

void SimHost::interface_lost(const std::error_code& why, TimePoint now) {
  if (interface_down_) return;
  interface_down_ = true;
  log_.warn("interface {}: {}; the devices wait for it (checked every {} ms)", interface_,
            why.message(), std::chrono::duration_cast<milliseconds>(kReopenPeriod).count());
  for (auto& d : devices_) {
    if (d->socket().is_open()) {
      (void)::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, d->socket().fd(), nullptr);
      d->socket().close();
    }
  }
  reopen_at_ = now + kReopenPeriod;
}

void SimHost::try_reopen(TimePoint now) {
  reopen_at_ = now + kReopenPeriod;
  if (socketcan::link_state(interface_) != socketcan::LinkState::kUp) return;
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    auto& d = *devices_[i];
    if (d.socket().is_open()) continue;
    if (d.open(interface_)) return;
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = i;
    (void)::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, d.socket().fd(), &ev);
  }
  interface_down_ = false;
  reopen_at_ = kNever;
  log_.info("interface {} is back", interface_);
}

void SimHost::on_socket(std::size_t index) {
  auto& d = *devices_[index];
  for (int i = 0; i < 64 && d.socket().is_open(); ++i) {
    auto r = d.socket().read();
    // Each frame at the time it is read: a frame that arrives while the ones
    // before it are answered (the last fragment after the first one's
    // acknowledgment) is late from its own arrival, not from the wake-up's.
    const TimePoint now = this->now();
    if (!r) {
      if (is(r.error(), EAGAIN)) return;
      if (interface_gone(r.error())) {
        interface_lost(r.error(), now);
      } else if (auto e = d.socket().take_error(); e && interface_gone(e)) {
        interface_lost(e, now);
      }
      return;
    }
    if (r->kind != socketcan::Received::Kind::kData || !d.powered()) continue;
    d.slave().on_frame(r->frame, now);
  }
}

std::string SimHost::status_line(SocketDevice& d, TimePoint now) {
  if (d.eds() != nullptr) return eds_status_line(d);
  auto& s = *d.cdn127();
  s.pump().advance(now);
  const auto& out = s.outputs();
  const auto& ain = s.pump().analog_inputs_raw();
  return fmt::format(
      "mac {} power {} network {} owner {} poll {} | outputs pump-on {} n2-ballast {} aout {} | "
      "running {} alarm {} warning {} n2-flow {} interlock {} ain1 {} ain2 {} | "
      "identity state {} status 0x{:04X} faults {}",
      d.mac().value(), on_off(d.powered()), sim::to_string(s.network_state()),
      s.owner() == 255 ? std::string("none") : std::to_string(s.owner()),
      s.poll_state() == sim::ConnectionState::kEstablished ? "established" : "not-established",
      on_off(out.pump_on), on_off(out.n2_ballast_on), out.analog_out_raw,
      on_off(s.pump().running()), on_off(s.pump().alarm_active()),
      on_off(s.pump().warning_active()), on_off(s.pump().n2_flow_ok()),
      on_off(s.pump().interlock_ok()), ain[0], ain[1], s.device().identity_state(),
      s.device().identity_status(), fault_list(s.device().faults()));
}

// A device driven by its EDS: its connections, its data and what its
// change-of-state connection did.
std::string SimHost::eds_status_line(SocketDevice& d) {
  const sim::EdsSlave& s = *d.eds();
  const auto established = [](sim::ConnectionState c) {
    return c == sim::ConnectionState::kEstablished ? "established" : "not-established";
  };
  const auto data = [&](std::uint16_t assembly) {
    // One word of hex digits, as read on the wire.
    return assembly == 0
               ? std::string("none")
               : fmt::format("{:02X}", fmt::join(s.objects().assembly_data(assembly), ""));
  };
  const auto& cos = s.cos_counters();
  const auto& strobe = s.strobe_counters();
  return fmt::format(
      "mac {} power {} network {} owner {} poll {} cos {} | eds \"{}\" | inputs {} outputs {} | "
      "cos produced {} acks {} retries {} given-up {} late {} | strobe {} commands {} responses {}",
      d.mac().value(), on_off(d.powered()), sim::to_string(s.network_state()),
      s.owner() == 255 ? std::string("none") : std::to_string(s.owner()),
      established(s.poll_state()), established(s.cos_state()),
      s.objects().file().device.product_name,
      data(s.connections().poll_connection().produced_assembly), data(s.poll_output_assembly()),
      cos.produced, cos.acks_received, cos.retries, cos.given_up, cos.late_acks,
      established(s.strobe_state()), strobe.commands, strobe.responses);
}

std::string SimHost::execute(const ControlCommand& c, TimePoint now) {
  std::vector<SocketDevice*> targets;
  for (auto& d : devices_) {
    if (!c.mac || d->mac().value() == *c.mac) targets.push_back(d.get());
  }
  if (c.mac && targets.empty()) return fmt::format("error: no device at MAC {}", *c.mac);

  switch (c.verb) {
    case Verb::kHelp:
      return "ok (see --help)";
    case Verb::kQuit:
      return "ok bye";
    case Verb::kStatus: {
      std::string lines;
      for (auto* d : targets) {
        if (!lines.empty()) lines += '\n';
        lines += "ok " + status_line(*d, now);
      }
      return lines;
    }
    case Verb::kPowerCycle:
      for (auto* d : targets) {
        d->power_off();
        d->power_on(now);
        log_.info("device {} power-cycled", d->mac().value());
      }
      return "ok";
    case Verb::kPowerOff:
      for (auto* d : targets) {
        d->power_off();
        log_.info("device {} powered off", d->mac().value());
      }
      return "ok";
    case Verb::kPowerOn:
      for (auto* d : targets) {
        if (!d->powered()) d->power_on(now);
        log_.info("device {} powered on", d->mac().value());
      }
      return "ok";
    case Verb::kFault:
      // "all": the CDN127s (a device run by its EDS has no faults simulated).
      if (c.mac && targets.front()->cdn127() == nullptr) {
        return fmt::format("error: device {} runs its EDS file: its faults are not simulated",
                           *c.mac);
      }
      for (auto* d : targets) {
        if (d->cdn127() == nullptr) continue;
        auto& device = d->cdn127()->device();
        sim::IdentityFaults f = device.faults();
        fault_flag(f, c.fault) = c.on;
        device.set_faults(f, now);
        log_.info("device {} faults: {}", d->mac().value(), fault_list(f));
      }
      return "ok";
    case Verb::kSet:
      break;
  }
  return set_input(*targets.front(), c, now);
}

std::string SimHost::set_input(SocketDevice& d, const ControlCommand& c, TimePoint now) {
  if (c.input == Input::kParam) {
    if (d.eds() == nullptr) {
      return fmt::format(
          "error: device {} is a CDN127: alarm, warning, n2-flow, interlock, "
          "ain1, ain2",
          d.mac().value());
    }
    sim::EdsSlave& s = *d.eds();
    const profiles::eds::Param* p = s.objects().file().param(c.param);
    if (p == nullptr) return fmt::format("error: the EDS has no Param{}", c.param);
    if (!s.objects().set_param_number(c.param, c.value)) {
      return fmt::format("error: {} is not a value of Param{} \"{}\"", c.value, c.param, p->name);
    }
    s.inputs_changed(now);
    return fmt::format("ok Param{} \"{}\" = {}", c.param, p->name, c.value);
  }
  if (d.cdn127() == nullptr) {
    return fmt::format("error: device {} runs its EDS file: set MAC param N VALUE",
                       d.mac().value());
  }
  auto& pump = d.cdn127()->pump();
  switch (c.input) {
    case Input::kParam:
      break;
    case Input::kAlarm:
      pump.set_alarm(c.on, now);
      break;
    case Input::kWarning:
      pump.set_warning(c.on);
      break;
    case Input::kN2Flow:
      pump.set_n2_flow_ok(c.on);
      break;
    case Input::kInterlock:
      pump.set_interlock_ok(c.on, now);
      break;
    case Input::kAnalog1:
    case Input::kAnalog2:
      if (!pump.set_analog_input(c.input == Input::kAnalog1 ? 0 : 1, c.raw)) {
        return "error: analog value out of range";
      }
      return fmt::format("ok {} counts ({:.3f} V)", c.raw, profiles::cdn127::raw_to_volts(c.raw));
  }
  return "ok";
}

void SimHost::run(int control_fd, bool quit_at_end, std::FILE* replies) {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  signals_.reset(::signalfd(-1, &set, SFD_NONBLOCK | SFD_CLOEXEC));
  for (auto [fd, token] : {std::pair{timer_.get(), kTimerToken},
                           {signals_.get(), kSignalToken},
                           {control_fd, kControlToken}}) {
    if (fd < 0) continue;
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = token;
    if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, fd, &ev) < 0) {
      throw std::system_error(errno_code(), "epoll_ctl (control input)");
    }
  }

  std::string pending;  // a control line not yet complete
  bool control_open = control_fd >= 0;
  for (;;) {
    TimePoint t = now();
    if (interface_down_ && t >= reopen_at_) try_reopen(t);
    for (auto& d : devices_) {
      if (!d->powered()) continue;
      if (t >= d->retry_at()) d->flush(t);
      while (d->slave().next_deadline() <= t) d->slave().on_timer(t);
      if (d->lost_interface()) {
        d->forget_interface();
        interface_lost(errno_code(ENETDOWN), t);
      }
    }

    const TimePoint next = next_deadline();
    itimerspec spec{};
    if (next != kNever) {
      const auto ns = std::max<std::int64_t>(next.time_since_epoch().count(), 1);
      spec.it_value.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
      spec.it_value.tv_nsec = static_cast<long>(ns % 1'000'000'000);
    }
    (void)::timerfd_settime(timer_.get(), TFD_TIMER_ABSTIME, &spec, nullptr);

    epoll_event events[16];
    const int n = ::epoll_wait(epoll_.get(), events, 16, -1);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::system_error(errno_code(), "epoll_wait");
    }
    t = now();
    for (int i = 0; i < n; ++i) {
      const std::uint64_t token = events[i].data.u64;
      if (token == kTimerToken) {
        std::uint64_t expiries = 0;
        (void)!::read(timer_.get(), &expiries, sizeof expiries);
      } else if (token == kSignalToken) {
        log_.info("signal: stopping");
        return;
      } else if (token == kControlToken) {
        char buf[1024];
        const ssize_t got = ::read(control_fd, buf, sizeof buf);
        if (got == 0 || (got < 0 && errno != EAGAIN && errno != EINTR)) {
          (void)::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, control_fd, nullptr);
          control_open = false;
          if (quit_at_end) return;
          continue;
        }
        if (got < 0) continue;
        pending.append(buf, static_cast<std::size_t>(got));
        std::size_t eol;
        while ((eol = pending.find('\n')) != std::string::npos) {
          const std::string line = pending.substr(0, eol);
          pending.erase(0, eol + 1);
          auto parsed = parse_control(line);
          if (std::holds_alternative<std::monostate>(parsed)) continue;
          if (auto* e = std::get_if<std::string>(&parsed)) {
            fmt::print(replies, "error: {}\n", *e);
          } else {
            const auto& c = std::get<ControlCommand>(parsed);
            if (c.verb == Verb::kHelp) {
              fmt::print(replies, "{}", control_help());
            }
            fmt::print(replies, "{}\n", execute(c, t));
            if (c.verb == Verb::kQuit) {
              std::fflush(replies);
              return;
            }
          }
          std::fflush(replies);
        }
      } else if (token < devices_.size()) {
        on_socket(static_cast<std::size_t>(token));
      }
    }
    (void)control_open;
  }
}

}  // namespace dnbridge::sim::host
