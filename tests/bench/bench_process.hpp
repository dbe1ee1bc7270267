#pragma once
// What the benchmarks share of processes: a process seen from /proc (CPU
// time, by thread, RSS), the bridge's or their own; child processes (the
// bridge, a benchmark's peer) started, read and stopped; and pacing.
#include <dds/version.h>
#include <fcntl.h>
#include <fmt/chrono.h>
#include <fmt/format.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "figures.hpp"

namespace dnbridge::bench {

// ---------------------------------------------------------------------------
// Clocks

inline void sleep_until_monotonic(std::int64_t t) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(t % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

// A duration given in microseconds, in the unit that reads best.
inline std::string duration_text(double us) {
  if (us >= 1e6) return fmt::format("{:.2f} s", us / 1e6);
  if (us >= 1e3) return fmt::format("{:.2f} ms", us / 1e3);
  return fmt::format("{:.1f} us", us);
}

// The first lines of every report: what ran, when and where, on which
// Cyclone DDS (domain and discovery tag when given), and how busy the machine
// was: figures are only as good as the machine is quiet.
inline void print_run_header(std::string_view title, int domain = -1, std::string_view tag = {}) {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  fmt::print("{}, {:%Y-%m-%d %H:%M:%S} UTC, host {}, {} CPU(s)\n", title,
             fmt::gmtime(std::time(nullptr)), host, std::thread::hardware_concurrency());
  fmt::print("DDS: Cyclone DDS {}, loopback only (lo, unicast discovery){}\n", DDS_VERSION,
             domain >= 0 ? fmt::format(", domain {}, tag {}", domain, tag) : std::string());
  fmt::print("load average at start: {}\n", load_average());
}

// Keeps the calling thread, and the threads and processes it starts after,
// on one CPU (none: -1).
inline bool pin_to_cpu(int cpu) {
  if (cpu < 0) return true;
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<std::size_t>(cpu), &set);
  return sched_setaffinity(0, sizeof set, &set) == 0;
}

// Asks the kernel to keep every CPU out of idle states that take longer than
// 0 us to leave, for as long as the returned descriptor is open (the PM QoS
// interface that latency tools such as cyclictest use): a CPU woken from a
// halt, on a virtual machine above all, adds tens of microseconds to a
// hand-over between threads, whatever the software. -1 when refused.
inline int hold_cpus_awake() {
  const int fd = open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  if (fd < 0) return -1;
  const std::int32_t zero = 0;
  if (write(fd, &zero, sizeof zero) != static_cast<ssize_t>(sizeof zero)) {
    close(fd);
    return -1;
  }
  return fd;
}

// ---------------------------------------------------------------------------
// A process seen from /proc: the bridge's, or the benchmark's own

struct ThreadTimes {
  std::string name;
  std::uint64_t ticks = 0;     // utime + stime
  std::uint64_t switches = 0;  // voluntary + involuntary context switches
};

// utime + stime (clock ticks) of a /proc/.../stat line; its name in `name`.
inline std::optional<std::uint64_t> stat_ticks(const std::filesystem::path& stat,
                                               std::string* name) {
  std::ifstream f(stat);
  std::string line;
  if (!std::getline(f, line)) return std::nullopt;
  const auto open = line.find('('), close = line.rfind(')');
  if (open == std::string::npos || close == std::string::npos || close + 2 > line.size()) {
    return std::nullopt;
  }
  if (name) *name = line.substr(open + 1, close - open - 1);
  std::istringstream rest(line.substr(close + 2));
  std::vector<std::string> fields{std::istream_iterator<std::string>(rest), {}};
  // Fields 14 and 15 of the line (utime, stime) are 12 and 13 after the name.
  if (fields.size() < 13) return std::nullopt;
  return std::stoull(fields[11]) + std::stoull(fields[12]);
}

// A "Key:   value ..." line of /proc/.../status, its first number.
inline std::uint64_t status_value(const std::filesystem::path& status, std::string_view key) {
  std::ifstream f(status);
  std::string line;
  while (std::getline(f, line)) {
    if (line.size() > key.size() && line.compare(0, key.size(), key) == 0 &&
        line[key.size()] == ':') {
      return std::stoull(line.substr(key.size() + 1));
    }
  }
  return 0;
}

// Clock ticks of /proc (utime, stime) in seconds.
inline double ticks_seconds(std::uint64_t ticks) {
  return static_cast<double>(ticks) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

// Clock ticks over `seconds` of wall time, in % of one core.
inline double core_percent(std::uint64_t ticks, double seconds) {
  return 100.0 * static_cast<double>(ticks) / static_cast<double>(sysconf(_SC_CLK_TCK)) / seconds;
}

struct ProcessSample {
  std::int64_t at = 0;       // monotonic ns
  std::uint64_t ticks = 0;   // the whole process
  std::uint64_t rss_kb = 0;  // VmRSS
  std::map<pid_t, ThreadTimes> threads;
};

// With `threads` false, the process's own figures only (quicker).
inline ProcessSample sample_process(pid_t pid, bool threads = true) {
  const std::filesystem::path dir = fmt::format("/proc/{}", pid);
  ProcessSample s;
  s.at = monotonic_ns();
  s.ticks = stat_ticks(dir / "stat", nullptr).value_or(0);
  s.rss_kb = status_value(dir / "status", "VmRSS");
  if (!threads) return s;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "task", ec)) {
    ThreadTimes t;
    const auto ticks = stat_ticks(entry.path() / "stat", &t.name);
    if (!ticks) continue;  // ended meanwhile
    t.ticks = *ticks;
    t.switches = status_value(entry.path() / "status", "voluntary_ctxt_switches") +
                 status_value(entry.path() / "status", "nonvoluntary_ctxt_switches");
    s.threads[static_cast<pid_t>(std::stol(entry.path().filename().string()))] = t;
  }
  return s;
}

// ---------------------------------------------------------------------------
// The bridge as a child process

inline pid_t spawn(const std::vector<std::string>& argv, int out_fd, int err_fd, int cpu) {
  // Made before fork(): the child only calls what is safe after it.
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const std::string cannot = "dnbridge bench: cannot run " + argv.at(0) + "\n";
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    if (cpu >= 0) {
      cpu_set_t set;
      CPU_ZERO(&set);
      CPU_SET(static_cast<std::size_t>(cpu), &set);
      if (sched_setaffinity(0, sizeof set, &set) != 0) _exit(126);
    }
    if (out_fd >= 0) dup2(out_fd, STDOUT_FILENO);
    if (err_fd >= 0) dup2(err_fd, STDERR_FILENO);
    execvp(args[0], args.data());
    (void)!write(STDERR_FILENO, cannot.data(), cannot.size());
    _exit(127);
  }
  return pid;
}

// A child process; its standard output when captured.
struct Child {
  pid_t pid = -1;
  int out = -1;
};

// Runs `argv` (a path, or a name looked up in PATH) on CPU `cpu` (any: -1)
// with standard output to a pipe (capture) or /dev/null, standard error
// inherited. Throws on failure to start.
inline Child spawn_child(const std::vector<std::string>& argv, bool capture, int cpu) {
  int fds[2] = {-1, -1};
  if (capture) {
    if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  } else {
    fds[1] = open("/dev/null", O_WRONLY | O_CLOEXEC);
  }
  Child c;
  try {
    c.pid = spawn(argv, fds[1], -1, cpu);
  } catch (...) {
    if (fds[0] >= 0) close(fds[0]);
    if (fds[1] >= 0) close(fds[1]);
    throw;
  }
  if (fds[1] >= 0) close(fds[1]);
  c.out = fds[0];
  return c;
}

// Exit status of a child (-1 when killed by a signal).
inline int wait_child(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Reads a child's output line by line, each read bounded by a deadline.
class LineReader {
 public:
  explicit LineReader(int fd) : fd_(fd) {}
  // The next line; nullopt at end of file or when `deadline` (monotonic ns)
  // passes first (timed_out() tells which).
  std::optional<std::string> next(std::int64_t deadline) {
    for (;;) {
      if (auto pos = buffer_.find('\n', start_); pos != std::string::npos) {
        std::string line = buffer_.substr(start_, pos - start_);
        start_ = pos + 1;
        return line;
      }
      // What was returned goes before more is read: a long output is not
      // moved once per line.
      buffer_.erase(0, start_);
      start_ = 0;
      if (eof_) return std::nullopt;
      const auto left = deadline - monotonic_ns();
      if (left <= 0) {
        timed_out_ = true;
        return std::nullopt;
      }
      pollfd p{fd_, POLLIN, 0};
      const int n =
          ::poll(&p, 1, static_cast<int>(std::min<std::int64_t>(left / 1'000'000 + 1, 1000)));
      if (n <= 0) continue;
      char chunk[65536];
      const ssize_t got = ::read(fd_, chunk, sizeof chunk);
      if (got <= 0) {
        eof_ = true;
        continue;
      }
      buffer_.append(chunk, static_cast<std::size_t>(got));
    }
  }
  bool timed_out() const { return timed_out_; }

 private:
  int fd_;
  std::string buffer_;
  std::size_t start_ = 0;  // where the next line begins in buffer_
  bool eof_ = false;
  bool timed_out_ = false;
};

// Hands every line of a child's output but its last, "done", to `on_line`,
// up to the end of that output or until `deadline` (monotonic ns) passes
// (then the child is killed), and waits for the child to exit. Throws when
// it failed or never said "done" (`role` names it in the message).
template <class OnLine>
void read_child_output(Child child, std::int64_t deadline, std::string_view role, OnLine on_line) {
  LineReader lines(child.out);
  bool done = false;
  while (auto line = lines.next(deadline)) {
    if (*line == "done") {
      done = true;
    } else {
      on_line(*line);
    }
  }
  if (lines.timed_out()) kill(child.pid, SIGKILL);
  close(child.out);
  const int status = wait_child(child.pid);
  if (status != 0 || !done) {
    throw std::runtime_error(fmt::format("the {} process failed (exit {})", role, status));
  }
}

inline std::string exit_text(int status) {
  if (WIFEXITED(status)) return fmt::format("exit {}", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return fmt::format("killed by signal {}", WTERMSIG(status));
  return "ended";
}

// `argv` run to its end: its standard output; its wait status in `status`.
inline std::string run_capture(const std::vector<std::string>& argv, int* status) {
  int fds[2] = {-1, -1};
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = spawn(argv, fds[1], -1, -1);
  close(fds[1]);
  std::string out;
  char chunk[4096];
  for (;;) {
    const ssize_t n = read(fds[0], chunk, sizeof chunk);
    if (n > 0) {
      out.append(chunk, static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  close(fds[0]);
  *status = 0;
  while (waitpid(pid, status, 0) < 0 && errno == EINTR) {
  }
  return out;
}

// `dnbridge --print-default-config`.
inline std::string default_config_text(const std::string& dnbridge) {
  int status = 0;
  const std::string text = run_capture({dnbridge, "--print-default-config"}, &status);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || text.empty()) {
    throw std::runtime_error(
        fmt::format("{} --print-default-config failed ({})", dnbridge, exit_text(status)));
  }
  return text;
}

// The embedded default (`dnbridge --print-default-config`) on DDS domain `domain`.
inline std::string default_config_on_domain(const std::string& dnbridge, int domain) {
  const std::string text = default_config_text(dnbridge);
  const std::regex domain_line(R"(^domain = \d+$)", std::regex::multiline);
  if (!std::regex_search(text, domain_line)) {
    throw std::runtime_error("the default configuration has no \"domain = N\" line");
  }
  return std::regex_replace(text, domain_line, fmt::format("domain = {}", domain));
}

// dnbridge running `config_text` (written to DIR/NAME.toml), its log
// (standard error) in DIR/NAME.log, on CPU `cpu` (any: -1). Stopped with
// SIGTERM, as systemd stops it.
class BridgeProcess {
 public:
  BridgeProcess(const std::string& dnbridge, const std::string& config_text,
                const std::filesystem::path& dir, const std::string& name, int cpu)
      : config_(dir / (name + ".toml")), log_(dir / (name + ".log")) {
    std::ofstream(config_) << config_text;
    const int log_fd = open(log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (log_fd < 0) throw std::runtime_error("cannot create " + log_.string());
    pid_ = spawn({dnbridge, "--config", config_.string()}, log_fd, log_fd, cpu);
    close(log_fd);
    pidfd_ = static_cast<int>(syscall(SYS_pidfd_open, pid_, 0));
    if (pidfd_ < 0) {
      kill(pid_, SIGKILL);
      (void)reap();
      throw std::runtime_error("pidfd_open failed (Linux 5.3 or later is needed)");
    }
  }
  BridgeProcess(const BridgeProcess&) = delete;
  BridgeProcess& operator=(const BridgeProcess&) = delete;
  ~BridgeProcess() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      (void)reap();
    }
    if (pidfd_ >= 0) close(pidfd_);
  }

  pid_t pid() const { return pid_; }
  const std::filesystem::path& log_path() const { return log_; }
  const std::filesystem::path& config_path() const { return config_; }

  // Still running? Otherwise how it ended.
  std::optional<std::string> ended() {
    if (pid_ <= 0) return ended_;
    pollfd p{pidfd_, POLLIN, 0};
    if (::poll(&p, 1, 0) <= 0) return std::nullopt;
    ended_ = exit_text(reap());
    return ended_;
  }

  // SIGTERM (an orderly stop: nodes idled and released), then waits for the
  // exit for at most `timeout_ms`; SIGKILL after that. How it ended.
  std::string stop(int timeout_ms) {
    if (pid_ <= 0) return ended_.value_or("ended");
    kill(pid_, SIGTERM);
    pollfd p{pidfd_, POLLIN, 0};
    int n;
    do {
      n = ::poll(&p, 1, timeout_ms);
    } while (n < 0 && errno == EINTR);
    if (n == 0) {
      kill(pid_, SIGKILL);
      ended_ = exit_text(reap()) +
               fmt::format(" (SIGKILL: not stopped {} ms after SIGTERM)", timeout_ms);
      return *ended_;
    }
    ended_ = exit_text(reap());
    return *ended_;
  }

 private:
  int reap() {
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
    return status;
  }

  std::filesystem::path config_, log_;
  pid_t pid_ = -1;
  int pidfd_ = -1;
  std::optional<std::string> ended_;
};

}  // namespace dnbridge::bench
