#include "system_fixture.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "adapters/dds/fields.hpp"

namespace dnbridge::system_test {

using namespace std::chrono_literals;

// --- Child -----------------------------------------------------------------

Child::Child(const std::vector<std::string>& argv, const fs::path& log) : log_(log) {
  // Everything the child needs is prepared before fork(): between fork and
  // exec only async-signal-safe calls (this process has DDS threads).
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const std::string log_path = log.string();
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) < 0) throw std::runtime_error("pipe2");
  const int out = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (out < 0) throw std::runtime_error("cannot create " + log_path);
  pid_ = ::fork();
  if (pid_ == 0) {
    ::dup2(pipe_fds[0], STDIN_FILENO);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(out, STDERR_FILENO);
    ::execv(args[0], args.data());
    _exit(127);
  }
  ::close(pipe_fds[0]);
  ::close(out);
  stdin_ = pipe_fds[1];
  if (pid_ < 0) throw std::runtime_error("fork");
}

Child::~Child() {
  if (pid_ > 0) (void)stop();
  if (stdin_ >= 0) ::close(stdin_);
}

void Child::send(const std::string& line) {
  const std::string l = line + "\n";
  if (::write(stdin_, l.data(), l.size()) != static_cast<ssize_t>(l.size())) {
    ADD_FAILURE() << "cannot write to the child's input: " << line;
  }
}

void Child::signal(int number) {
  if (pid_ > 0) ::kill(pid_, number);
}

bool Child::running() {
  if (pid_ <= 0) return false;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    status_ = status;
    pid_ = -1;
    return false;
  }
  return true;
}

int Child::stop(std::chrono::milliseconds grace) {
  if (pid_ <= 0) return status_;
  ::kill(pid_, SIGTERM);
  const auto until = std::chrono::steady_clock::now() + grace;
  while (std::chrono::steady_clock::now() < until) {
    if (!running()) return status_;
    std::this_thread::sleep_for(50ms);
  }
  ::kill(pid_, SIGKILL);
  ::waitpid(pid_, &status_, 0);
  pid_ = -1;
  ADD_FAILURE() << log_.filename() << ": did not stop within " << grace.count() << " ms of SIGTERM";
  return status_;
}

// --- Capture ---------------------------------------------------------------

Capture::Capture(const std::string& interface, const fs::path& file)
    : epoch_(std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::system_clock::now().time_since_epoch())),
      writer_(file.string(), TimePoint{}, epoch_) {
  socketcan::SocketOptions o;  // every data frame, kernel timestamps
  auto s = socketcan::CanSocket::open(interface, o);
  if (!s) throw std::system_error(s.error(), "capture on " + interface);
  socket_ = std::move(*s);
  thread_ = std::thread([this] { run(); });
}

Capture::~Capture() { (void)stop(); }

void Capture::run() {
  while (!stop_) {
    pollfd p{socket_.fd(), POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    for (;;) {
      auto r = socket_.read();
      if (!r) break;
      if (r->kind != socketcan::Received::Kind::kData) continue;
      const auto wall =
          r->kernel_time.value_or(std::chrono::duration_cast<std::chrono::nanoseconds>(
              std::chrono::system_clock::now().time_since_epoch()));
      // TimePoint{} is the writer's start, stamped as the wall time at construction.
      const auto since = std::chrono::duration_cast<Duration>(wall - epoch_);
      writer_.write(r->frame, TimePoint{} + std::max(since, Duration::zero()));
      frames_.push_back(r->frame);
    }
  }
}

std::uint64_t Capture::stop() {
  if (thread_.joinable()) {
    stop_ = true;
    thread_.join();
    writer_.close();
  }
  return frames_.size();
}

// --- Supervisor ------------------------------------------------------------

Supervisor::Supervisor(const std::string& rack)
    : rack_(rack),
      participant_(0, "system-test supervisor"),
      pump_topic_(participant_),
      port_topic_(participant_),
      command_topic_(participant_),
      pump_reader_(participant_, pump_topic_, dds::state_reader_qos()),
      port_reader_(participant_, port_topic_, dds::state_reader_qos()),
      command_writer_(participant_, command_topic_,
                      dds::command_writer_qos(dds::rack_partitions(rack_), 10, seconds(10))),
      pump_data_(pump_reader_, DDS_ANY_STATE),
      port_data_(port_reader_, DDS_ANY_STATE),
      waitset_(participant_) {
  waitset_.attach(pump_data_, 1);
  waitset_.attach(port_data_, 2);
}

void Supervisor::update() {
  if (auto taken = pump_reader_.take(); taken) {
    for (auto& s : *taken) {
      if (!s.valid_data() || dds::view(s->rack) != rack_) continue;
      PumpSeen& p = pumps_[PumpKey{std::string(dds::view(s->port)), s->mac}];
      p.online = s->online;
      p.pump_running = s->pump_running;
      p.alarm_active = s->alarm_active;
      p.outputs_idle = s->outputs_idle;
      p.idle_reason = std::string(dds::view(s->idle_reason));
      p.pump_on = s->pump_on;
      p.n2_ballast_on = s->n2_ballast_on;
      p.analog_output_raw = s->analog_output_raw;
      p.analog_in1 = s->analog_input_count > 0 ? s->analog_input_volts[0] : 0.0F;
      p.commanded_by = std::string(dds::view(s->commanded_by));
      p.source_time = s.info().source_timestamp();
      p.received = dds::dds_now();
    }
  }
  if (auto taken = port_reader_.take(); taken) {
    for (auto& s : *taken) {
      if (!s.valid_data() || dds::view(s->rack) != rack_) continue;
      PortSeen& p = ports_[std::string(dds::view(s->port))];
      p.bus_state = s->bus_state;
      p.state = s->state;
      p.reason = std::string(dds::view(s->reason));
      p.nodes_online = s->nodes_online;
      p.nodes_configured = s->nodes_configured;
      p.can_interface = std::string(dds::view(s->can_interface));
    }
  }
}

bool Supervisor::wait_until(const std::function<bool()>& done, std::chrono::seconds timeout) {
  const auto until = std::chrono::steady_clock::now() + patience(timeout);
  for (;;) {
    update();
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= until) return false;
    (void)waitset_.wait(milliseconds(200));
  }
}

bool Supervisor::command(const std::string& port, unsigned mac, bool pump_on, bool n2_ballast_on,
                         std::uint16_t analog_output_raw) {
  dds::Owned<dnbridge_PumpCommand> c;
  dds::set_string(c->rack, rack_);
  dds::set_string(c->port, port);
  c->mac = static_cast<std::uint8_t>(mac);
  c->pump_on = pump_on;
  c->n2_ballast_on = n2_ballast_on;
  c->analog_output_raw = analog_output_raw;
  dds::set_string(c->issuer, "system-test");
  return command_writer_.write(*c).ok();
}

bool Supervisor::online(const std::string& port, unsigned mac) const {
  auto it = pumps_.find(PumpKey{port, mac});
  return it != pumps_.end() && it->second.online;
}

bool Supervisor::all_online(const std::string& port, const std::vector<unsigned>& macs) const {
  for (auto m : macs) {
    if (!online(port, m)) return false;
  }
  return true;
}

std::string Supervisor::describe() const {
  std::string s;
  for (const auto& [name, p] : ports_) {
    s += fmt::format("port {} ({}): state {}, bus {}, {}/{} online, reason \"{}\"\n", name,
                     p.can_interface, static_cast<int>(p.state), static_cast<int>(p.bus_state),
                     p.nodes_online, p.nodes_configured, p.reason);
  }
  for (const auto& [k, p] : pumps_) {
    s += fmt::format(
        "pump {}/{}: online {}, running {}, alarm {}, pump_on {}, n2_ballast_on {}, aout {}, "
        "ain1 {:.3f}, {}\n",
        k.port, k.mac, p.online, p.pump_running, p.alarm_active, p.pump_on, p.n2_ballast_on,
        p.analog_output_raw, p.analog_in1,
        p.outputs_idle ? fmt::format("\"{}\"", p.idle_reason) : "commanded by " + p.commanded_by);
  }
  return s;
}

// --- helpers ---------------------------------------------------------------

double guest_slowdown() {
  const char* s = std::getenv("DNBRIDGE_SYSTEM_SLOWDOWN");
  double factor = s ? std::strtod(s, nullptr) : 1.0;
  // A factor outside [1, 50] is a measurement gone wrong, not a machine.
  return std::isfinite(factor) ? std::clamp(factor, 1.0, 50.0) : 1.0;
}

std::chrono::milliseconds patience(std::chrono::milliseconds base) {
  static const double factor = guest_slowdown();
  return std::chrono::milliseconds(static_cast<std::chrono::milliseconds::rep>(
      std::ceil(static_cast<double>(base.count()) * factor)));
}

fs::path work_dir() {
  // run_in_vm.sh gives each test a directory of its own.
  const char* w = std::getenv("DNBRIDGE_SYSTEM_WORK");
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path dir = w ? fs::path(w)
                   : fs::temp_directory_path() / "dnbridge-system" / (info ? info->name() : "run");
  fs::create_directories(dir);
  return dir;
}

int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string rack_config(const std::string& rack, const std::vector<PortSpec>& ports) {
  // Short expected packet rates and allocation retries: lost nodes are
  // noticed and found again within seconds.
  std::string s = fmt::format(
      "rack = \"{}\"\ndomain = 0\nlog_level = \"info\"\n[defaults]\npoll_period_ms = {}\n"
      "expected_packet_rate_ms = {}\n",
      rack, kPollPeriod.count(), kExpectedPacketRate.count());
  for (const auto& p : ports) {
    s += fmt::format(
        "[[port]]\nname = \"{}\"\ninterface = \"{}\"\nbitrate = 500000\n"
        "allocate_retry_max_ms = 1000\n",
        p.name, p.interface);
    for (auto m : p.macs) {
      s += fmt::format("  [[port.node]]\n  mac = {}\n  name = \"pump-{}\"\n", m, m);
      if (auto it = p.node_settings.find(m); it != p.node_settings.end()) {
        s += it->second + "\n";
      }
    }
  }
  return s;
}

}  // namespace dnbridge::system_test
