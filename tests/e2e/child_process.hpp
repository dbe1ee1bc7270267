#pragma once
// A program run as a child process for the length of a test, with this
// process's environment (plus what the test adds) and, if asked, its stderr
// on a pipe for the test to read, or its stdin and stdout on a socket the
// test talks to it through, a line at a time. Killed if the test ends before
// it exited.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

extern char** environ;

namespace dnbridge::e2e {

struct ChildOptions {
  std::vector<std::string> env;  // NAME=VALUE, replacing this process's NAME
  bool capture_stderr = false;
  // stdin and stdout on one end of a socket pair, the other end the test's
  // (send_line, read_line): a socket rather than pipes, so that writing to
  // a child that died is an error, not a SIGPIPE for the test.
  bool control = false;
};

class ChildProcess {
 public:
  explicit ChildProcess(std::vector<std::string> args, const ChildOptions& options = {}) {
    std::vector<std::string> env = options.env;
    for (char** e = environ; *e != nullptr; ++e) {
      const std::string entry(*e);
      const std::string name = entry.substr(0, entry.find('=') + 1);
      bool replaced = false;
      for (const auto& added : options.env) replaced = replaced || added.rfind(name, 0) == 0;
      if (!replaced) env.push_back(entry);
    }
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<char*> envp;
    for (auto& e : env) envp.push_back(e.data());
    envp.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    int err[2] = {-1, -1};
    if (options.capture_stderr && pipe2(err, O_CLOEXEC) == 0) {
      posix_spawn_file_actions_adddup2(&actions, err[1], STDERR_FILENO);
    }
    int control[2] = {-1, -1};
    if (options.control && socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, control) == 0) {
      posix_spawn_file_actions_adddup2(&actions, control[1], STDIN_FILENO);
      posix_spawn_file_actions_adddup2(&actions, control[1], STDOUT_FILENO);
    }
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), envp.data()) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
    if (err[1] >= 0) close(err[1]);
    if (control[1] >= 0) close(control[1]);
    stderr_ = err[0];
    control_ = control[0];
  }
  ~ChildProcess() {
    if (pid_ > 0) {
      (void)kill(pid_, SIGKILL);
      (void)waitpid(pid_, nullptr, 0);
    }
    if (stderr_ >= 0) close(stderr_);
    if (control_ >= 0) close(control_);
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  bool signal(int sig) const { return pid_ > 0 && kill(pid_, sig) == 0; }
  // The read end of its stderr (ChildOptions::capture_stderr), else -1.
  int stderr_fd() const { return stderr_; }
  // Waits for the exit; its status (-1 if it did not exit normally).
  int wait() {
    int status = 0;
    if (pid_ <= 0 || waitpid(pid_, &status, 0) != pid_) return -1;
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  // The same, for at most `timeout` (the exit is an event on a pidfd);
  // nullopt if it has not exited by then.
  std::optional<int> wait_for(std::chrono::milliseconds timeout) {
    if (pid_ <= 0) return std::nullopt;
    const int fd = static_cast<int>(syscall(SYS_pidfd_open, pid_, 0));
    if (fd < 0) return std::nullopt;
    pollfd p{fd, POLLIN, 0};
    const int n = poll(&p, 1, static_cast<int>(timeout.count()));
    close(fd);
    if (n != 1) return std::nullopt;
    return wait();
  }

  // ChildOptions::capture_stderr: reads its stderr, appending to `seen`,
  // until `text` is in `seen` (true) or `timeout` passed or stderr closed.
  bool read_stderr_until(std::string& seen, std::string_view text,
                         std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (seen.find(text) == std::string::npos) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (stderr_ < 0 || left.count() <= 0) return false;
      pollfd p{stderr_, POLLIN, 0};
      if (poll(&p, 1, static_cast<int>(left.count())) != 1) return false;
      char buf[4096];
      const ssize_t n = read(stderr_, buf, sizeof buf);
      if (n <= 0) return false;
      seen.append(buf, static_cast<std::size_t>(n));
    }
    return true;
  }

  // ChildOptions::control: the end of its stdin (its stdout stays open).
  bool close_input() const { return control_ >= 0 && shutdown(control_, SHUT_WR) == 0; }
  // ChildOptions::control: one line to its stdin ('\n' added).
  bool send_line(const std::string& line) const {
    const std::string text = line + "\n";
    return control_ >= 0 && send(control_, text.data(), text.size(), MSG_NOSIGNAL) ==
                                static_cast<ssize_t>(text.size());
  }
  // The next line it wrote to its stdout (without '\n'); nullopt when none
  // came within `timeout` or its stdout closed.
  std::optional<std::string> read_line(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      if (const auto end = output_.find('\n'); end != std::string::npos) {
        std::string line = output_.substr(0, end);
        output_.erase(0, end + 1);
        return line;
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (control_ < 0 || left.count() < 0) return std::nullopt;
      pollfd p{control_, POLLIN, 0};
      if (poll(&p, 1, static_cast<int>(left.count())) != 1) return std::nullopt;
      char buf[512];
      const ssize_t n = read(control_, buf, sizeof buf);
      if (n <= 0) return std::nullopt;
      output_.append(buf, static_cast<std::size_t>(n));
    }
  }

 private:
  pid_t pid_ = -1;
  int stderr_ = -1;
  int control_ = -1;
  std::string output_;  // read from the control socket, not yet a whole line
};

}  // namespace dnbridge::e2e
