#pragma once
// The commands a test's helper program reads from its standard input (the
// test's control socket, e2e::ChildOptions::control): whole lines, as they
// come, without waiting longer than the program's loop allows.
#include <poll.h>
#include <unistd.h>

#include <string>

namespace dnbridge::support {

class StdinLines {
 public:
  // Waits up to `timeout_ms` for input, then calls `line` with each whole
  // line read (without its '\n'); false at the end of stdin.
  template <class F>
  bool read(int timeout_ms, F&& line) {
    pollfd p{STDIN_FILENO, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) != 1) return true;
    char buf[512];
    const ssize_t n = ::read(STDIN_FILENO, buf, sizeof buf);
    if (n <= 0) return false;
    input_.append(buf, static_cast<std::size_t>(n));
    for (auto end = input_.find('\n'); end != std::string::npos; end = input_.find('\n')) {
      line(input_.substr(0, end));
      input_.erase(0, end + 1);
    }
    return true;
  }

 private:
  std::string input_;  // read, not yet a whole line
};

}  // namespace dnbridge::support
