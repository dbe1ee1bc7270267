#pragma once
// A program run as a child process for the length of a test, with this
// process's environment (plus what the test adds) and, if asked, its stderr
// on a pipe for the test to read. Killed if the test ends before it exited.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

extern char** environ;

namespace dnbridge::e2e {

struct ChildOptions {
  std::vector<std::string> env;  // NAME=VALUE, replacing this process's NAME
  bool capture_stderr = false;
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
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), envp.data()) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
    if (err[1] >= 0) close(err[1]);
    stderr_ = err[0];
  }
  ~ChildProcess() {
    if (pid_ > 0) {
      (void)kill(pid_, SIGKILL);
      (void)waitpid(pid_, nullptr, 0);
    }
    if (stderr_ >= 0) close(stderr_);
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

 private:
  pid_t pid_ = -1;
  int stderr_ = -1;
};

}  // namespace dnbridge::e2e
