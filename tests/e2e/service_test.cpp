// The dnbridge executable under a service manager's eye, the test being the
// manager: it binds an AF_UNIX datagram socket, runs dnbridge with
// NOTIFY_SOCKET, WATCHDOG_USEC and WATCHDOG_PID (the process's own pid, as
// systemd sets it) and reads what sd_notify(3) sends there: READY=1,
// STATUS=, WATCHDOG=1, STOPPING=1 (dnbridge@.service is Type=notify with
// WatchdogSec=).
//
// A stalled port loop is made as a debugger stops one thread: the loop's
// thread ("port A", PortLoop names it) seized with ptrace and interrupted
// while the rest of the process runs on; detached, it goes on. Nothing is
// added to the product for it.
//
// Every wait is for an event (a datagram, a log line), bounded; the one
// "nothing arrives" check waits out a bounded window of the watchdog's own
// period.
#include <dirent.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/ptrace.h>
#include <sys/socket.h>
#include <sys/un.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "dds/dds_fixture.hpp"
#include "support/simulated_rack.hpp"

namespace dnbridge::e2e {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// WatchdogSec=3 s: WATCHDOG=1 every 1.5 s, the shortest period the bridge
// takes without a warning (its loops sleep up to 1 s when idle).
constexpr auto kWatchdog = 3s;
constexpr auto kFeedInterval = kWatchdog / 2;

// One datagram: its NAME=VALUE lines, and when it arrived.
struct Notification {
  std::vector<std::string> lines;
  Clock::time_point at;
  bool has(const std::string& line) const {
    for (const auto& l : lines) {
      if (l == line) return true;
    }
    return false;
  }
  std::optional<std::string> value(const std::string& name) const {
    for (const auto& l : lines) {
      if (l.rfind(name + "=", 0) == 0) return l.substr(name.size() + 1);
    }
    return std::nullopt;
  }
};

// The manager's side: the notification socket, the child, its stderr.
class ServiceManager {
 public:
  // WATCHDOG_USEC is `watchdog`.
  explicit ServiceManager(std::vector<std::string> dnbridge_args,
                          std::chrono::microseconds watchdog = kWatchdog) {
    path_ = std::filesystem::temp_directory_path() /
            ("dnbridge-notify-" + std::to_string(getpid()) + "-" + std::to_string(++count_));
    std::filesystem::remove(path_);
    socket_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, path_.c_str(), sizeof addr.sun_path - 1);
    if (socket_ < 0 ||
        ::bind(socket_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      ADD_FAILURE() << "notification socket " << path_ << ": " << std::strerror(errno);
      return;
    }
    // WATCHDOG_PID is the service's main pid: the shell's, which exec()
    // makes dnbridge's.
    std::vector<std::string> args{"/bin/sh", "-c", "WATCHDOG_PID=$$ exec \"$0\" \"$@\"",
                                  DNBRIDGE_BINARY};
    args.insert(args.end(), dnbridge_args.begin(), dnbridge_args.end());
    ChildOptions options;
    options.env = {"NOTIFY_SOCKET=" + path_.string(),
                   "WATCHDOG_USEC=" + std::to_string(watchdog.count())};
    options.capture_stderr = true;
    child_.emplace(std::move(args), options);
  }
  ~ServiceManager() {
    child_.reset();
    if (socket_ >= 0) ::close(socket_);
    std::filesystem::remove(path_);
  }

  ChildProcess& child() { return *child_; }

  // Reads notifications and log output until `done()` holds or `timeout`
  // passes; whether it held.
  bool until(const std::function<bool()>& done, Clock::duration timeout) {
    const auto deadline = Clock::now() + timeout;
    while (!done()) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      if (left <= 0ms) return false;
      pollfd fds[2] = {{socket_, POLLIN, 0}, {child_->stderr_fd(), POLLIN, 0}};
      const int n = ::poll(fds, stderr_open_ ? 2 : 1, static_cast<int>(left.count()) + 1);
      if (n < 0 && errno != EINTR) return false;
      if (n <= 0) continue;
      if (fds[0].revents & POLLIN) receive();
      if (stderr_open_ && fds[1].revents) read_log();
    }
    return true;
  }

  // After the child exited: whatever it sent that was not read yet.
  void drain() {
    while (receive()) {
    }
    while (stderr_open_) read_log();
  }

  const std::vector<Notification>& notifications() const { return notifications_; }
  const std::string& log() const { return log_; }
  bool logged(const std::string& text) const { return log_.find(text) != std::string::npos; }

  // Notifications with line `line`, and their times.
  std::vector<Clock::time_point> times_of(const std::string& line) const {
    std::vector<Clock::time_point> t;
    for (const auto& n : notifications_) {
      if (n.has(line)) t.push_back(n.at);
    }
    return t;
  }
  std::size_t count(const std::string& line) const { return times_of(line).size(); }
  // The index of the first notification with `line`, or -1.
  long first(const std::string& line) const {
    for (std::size_t i = 0; i < notifications_.size(); ++i) {
      if (notifications_[i].has(line)) return static_cast<long>(i);
    }
    return -1;
  }
  // The latest STATUS= so far ("" if none).
  std::string status() const {
    for (auto it = notifications_.rbegin(); it != notifications_.rend(); ++it) {
      if (auto s = it->value("STATUS")) return *s;
    }
    return {};
  }

 private:
  bool receive() {
    char buf[4096];
    const ssize_t n = ::recv(socket_, buf, sizeof buf, MSG_DONTWAIT);
    if (n <= 0) return false;
    Notification note{{}, Clock::now()};
    std::string text(buf, static_cast<std::size_t>(n));
    for (std::size_t at = 0; at < text.size();) {
      const auto end = text.find('\n', at);
      note.lines.push_back(text.substr(at, end == std::string::npos ? end : end - at));
      at = end == std::string::npos ? text.size() : end + 1;
    }
    notifications_.push_back(std::move(note));
    return true;
  }
  void read_log() {
    char buf[4096];
    const ssize_t n = ::read(child_->stderr_fd(), buf, sizeof buf);
    if (n > 0) {
      log_.append(buf, static_cast<std::size_t>(n));
    } else {
      stderr_open_ = false;
    }
  }

  static inline int count_ = 0;
  std::filesystem::path path_;
  int socket_ = -1;
  std::optional<ChildProcess> child_;
  bool stderr_open_ = true;
  std::vector<Notification> notifications_;
  std::string log_;
};

// One thread of another process stopped as a debugger stops it
// (PTRACE_SEIZE, then PTRACE_INTERRUPT: no signal, the other threads run
// on), until destroyed (PTRACE_DETACH).
class StoppedThread {
 public:
  explicit StoppedThread(pid_t tid) : tid_(tid) {
    if (::ptrace(PTRACE_SEIZE, tid_, nullptr, nullptr) != 0) {
      error_ = std::string("PTRACE_SEIZE: ") + std::strerror(errno);
      return;
    }
    int status = 0;
    if (::ptrace(PTRACE_INTERRUPT, tid_, nullptr, nullptr) != 0) {
      error_ = std::string("PTRACE_INTERRUPT: ") + std::strerror(errno);
    } else if (::waitpid(tid_, &status, __WALL) != tid_ || !WIFSTOPPED(status)) {
      error_ = "the thread did not stop";
    }
  }
  ~StoppedThread() { (void)::ptrace(PTRACE_DETACH, tid_, nullptr, nullptr); }
  StoppedThread(const StoppedThread&) = delete;
  StoppedThread& operator=(const StoppedThread&) = delete;

  // Empty when the thread is stopped.
  const std::string& error() const { return error_; }

 private:
  pid_t tid_;
  std::string error_;
};

// The thread of `pid` named `name` (/proc/PID/task/TID/comm), or -1.
pid_t thread_named(pid_t pid, const std::string& name) {
  const std::filesystem::path tasks = "/proc/" + std::to_string(pid) + "/task";
  std::error_code ec;
  for (const auto& task : std::filesystem::directory_iterator(tasks, ec)) {
    std::ifstream comm(task.path() / "comm");
    std::string line;
    if (std::getline(comm, line) && line == name) return std::stoi(task.path().filename().string());
  }
  return -1;
}

TEST(ServiceNotify, ReadyStatusWatchdogAndStoppingFromTheDnbridgeProcess) {
  ServiceManager manager({"--simulate"});
  ASSERT_TRUE(manager.child().running());

  // Ready once the port's MAC check is over, with the status line.
  ASSERT_TRUE(manager.until([&] { return manager.first("READY=1") >= 0; }, 15s)) << manager.log();
  const auto ready = static_cast<std::size_t>(manager.first("READY=1"));
  const auto& note = manager.notifications()[ready];
  ASSERT_TRUE(note.value("STATUS").has_value()) << "READY=1 without STATUS=";
  EXPECT_NE(note.value("STATUS")->find("/8 nodes online (A "), std::string::npos)
      << *note.value("STATUS");
  // Before it, only start-up status lines.
  for (std::size_t i = 0; i < ready; ++i) {
    if (auto s = manager.notifications()[i].value("STATUS")) {
      EXPECT_EQ(s->rfind("start-up checks: ", 0), 0u) << *s;
    }
  }
  // The status follows the rack: every pump online.
  ASSERT_TRUE(manager.until([&] { return manager.status() == "8/8 nodes online (A 8/8)"; }, 15s))
      << manager.status() << "\n"
      << manager.log();

  // Fed periodically: at the WATCHDOG_USEC / 2 cadence, never later than
  // WATCHDOG_USEC (systemd would have restarted it) and never much sooner.
  ASSERT_TRUE(manager.until([&] { return manager.count("WATCHDOG=1") >= 4; }, 4 * kWatchdog))
      << manager.log();
  const auto fed = manager.times_of("WATCHDOG=1");
  for (std::size_t i = 1; i < fed.size(); ++i) {
    const auto gap = fed[i] - fed[i - 1];
    EXPECT_GE(gap, kFeedInterval * 2 / 3) << "feed " << i;
    EXPECT_LT(gap, std::chrono::duration_cast<Clock::duration>(kWatchdog)) << "feed " << i;
  }
  EXPECT_EQ(manager.count("READY=1"), 1u);
  EXPECT_FALSE(manager.logged("is too short")) << manager.log();

  ASSERT_TRUE(manager.child().signal(SIGTERM));
  ASSERT_TRUE(manager.until([&] { return manager.first("STOPPING=1") >= 0; }, 10s))
      << manager.log();
  const auto stopping = static_cast<std::size_t>(manager.first("STOPPING=1"));
  EXPECT_TRUE(manager.notifications()[stopping].value("STATUS").has_value());
  EXPECT_EQ(manager.child().wait(), 0);
  manager.drain();
  for (std::size_t i = stopping; i < manager.notifications().size(); ++i) {
    EXPECT_FALSE(manager.notifications()[i].has("WATCHDOG=1")) << "fed after STOPPING=1";
  }
}

// Just under 3 s: warned, with the shortest period the bridge takes (3 s
// itself, which the other tests use, is taken without a word).
TEST(ServiceNotify, AWatchdogPeriodUnderThreeSecondsIsWarnedOf) {
  ServiceManager manager({"--simulate"}, kWatchdog - 1us);
  ASSERT_TRUE(manager.child().running());
  ASSERT_TRUE(manager.until([&] { return manager.logged("or more"); }, 15s)) << manager.log();
  EXPECT_TRUE(manager.logged(
      "systemd: WatchdogSec=2999 ms is too short: the port loops are checked every half "
      "period, and an idle one may go 1.5 s without a round; use 3 s or more"))
      << manager.log();
  ASSERT_TRUE(manager.child().signal(SIGTERM));
  EXPECT_EQ(manager.child().wait(), 0);
}

TEST(ServiceNotify, AStalledPortLoopStarvesTheWatchdogUntilItAdvancesAgain) {
  ServiceManager manager({"--simulate"});
  ASSERT_TRUE(manager.child().running());
  // A rack at work: ready, and fed since.
  ASSERT_TRUE(manager.until(
      [&] {
        const long ready = manager.first("READY=1");
        return ready >= 0 && manager.first("WATCHDOG=1") >= 0 &&
               manager.times_of("WATCHDOG=1").back() >
                   manager.notifications()[static_cast<std::size_t>(ready)].at;
      },
      15s))
      << manager.log();
  const pid_t loop = thread_named(manager.child().pid(), "port A");
  ASSERT_GT(loop, 0) << "no thread named \"port A\" in process " << manager.child().pid();

  std::size_t fed_before_recovery = 0;
  {
    StoppedThread stopped(loop);
    ASSERT_EQ(stopped.error(), "") << "ptrace of thread " << loop;
    // Seen at the first check with no progress since the previous one: two
    // check intervals at most.
    ASSERT_TRUE(manager.until([&] { return manager.logged("port A: loop stalled"); },
                              2 * kFeedInterval + 2s))
        << manager.log();
    EXPECT_TRUE(manager.logged("error systemd: port A: loop stalled")) << manager.log();
    // And the status line says it.
    ASSERT_TRUE(manager.until(
        [&] { return manager.status().find("/8: loop stalled)") != std::string::npos; }, 2s))
        << manager.status();

    // Starved: nothing fed for longer than the watchdog period would allow.
    fed_before_recovery = manager.count("WATCHDOG=1");
    EXPECT_FALSE(manager.until([&] { return manager.count("WATCHDOG=1") > fed_before_recovery; },
                               kWatchdog + 500ms))
        << "WATCHDOG=1 sent while port A's loop was stopped";
    // Said once, not at every check.
    std::size_t said = 0;
    for (std::size_t at = manager.log().find("loop stalled"); at != std::string::npos;
         at = manager.log().find("loop stalled", at + 1)) {
      ++said;
    }
    EXPECT_EQ(said, 1u) << manager.log();
  }  // detached: the loop goes on

  ASSERT_TRUE(manager.until([&] { return manager.count("WATCHDOG=1") > fed_before_recovery; },
                            2 * kFeedInterval + 2s))
      << manager.log();
  EXPECT_TRUE(manager.logged("port A: loop advances again")) << manager.log();

  ASSERT_TRUE(manager.child().signal(SIGTERM));
  ASSERT_TRUE(manager.until([&] { return manager.first("STOPPING=1") >= 0; }, 10s))
      << manager.log();
  EXPECT_EQ(manager.child().wait(), 0);
}

// A rack service starts with a CAN interface missing (here can7: on a host
// whose kernel has no SocketCAN at all, or has it without a can7): the port
// says so, the service is ready, and the other port runs.
TEST(ServiceNotify, AnAbsentCanInterfaceIsReportedAndDoesNotHoldReadinessBack) {
  std::string text = support::simulated_rack_config(dds::testing::test_domain());
  text +=
      "\n[[port]]\nname = \"B\"\ninterface = \"can7\"\nbitrate = 500000\n"
      "  [[port.node]]\n  mac = 9\n  name = \"pump-9\"\n";
  const auto config = std::filesystem::temp_directory_path() /
                      ("dnbridge-service-" + std::to_string(getpid()) + ".toml");
  std::ofstream(config) << text;

  ServiceManager manager({"--config", config.string()});
  ASSERT_TRUE(manager.child().running());
  ASSERT_TRUE(manager.until([&] { return manager.first("READY=1") >= 0; }, 15s)) << manager.log();
  const auto& ready = manager.notifications()[static_cast<std::size_t>(manager.first("READY=1"))];
  ASSERT_TRUE(ready.value("STATUS").has_value());
  EXPECT_NE(ready.value("STATUS")->find(", B 0/1: interface can7"), std::string::npos)
      << *ready.value("STATUS");
  EXPECT_TRUE(manager.logged("port B: interface can7")) << manager.log();
  EXPECT_TRUE(
      manager.logged("the master starts (duplicate MAC ID check, then scanning) when the "
                     "interface is up"))
      << manager.log();
  // Port A runs its rack meanwhile.
  ASSERT_TRUE(manager.until(
      [&] {
        return manager.status().rfind("8/9 nodes online (A 8/8, B 0/1: interface can7", 0) == 0;
      },
      15s))
      << manager.status();
  // Port B's loop, waiting for its interface, goes round all the same: fed.
  ASSERT_TRUE(manager.until([&] { return manager.count("WATCHDOG=1") >= 2; }, 2 * kWatchdog))
      << manager.log();
  EXPECT_FALSE(manager.logged("loop stalled")) << manager.log();

  ASSERT_TRUE(manager.child().signal(SIGTERM));
  ASSERT_TRUE(manager.until([&] { return manager.first("STOPPING=1") >= 0; }, 10s))
      << manager.log();
  EXPECT_EQ(manager.child().wait(), 0);
  std::filesystem::remove(config);
}

}  // namespace
}  // namespace dnbridge::e2e
