#pragma once
// Logging through an injected sink. The core formats a message only when the
// sink wants that level; anything on the frame path goes through a RateLimiter.
#include <fmt/format.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

#include "bridge/common/time.hpp"

namespace dnbridge {

enum class LogLevel : std::uint8_t { kTrace, kDebug, kInfo, kWarn, kError };

std::string_view to_string(LogLevel level) noexcept;

class LogSink {
 public:
  virtual ~LogSink() = default;
  virtual bool enabled(LogLevel level) const noexcept = 0;
  virtual void write(LogLevel level, std::string_view component, std::string_view message) = 0;
};

// A sink that drops everything.
LogSink& null_log_sink() noexcept;

// A component's handle on a sink: "port can0", "node 12", ...
class Logger {
 public:
  Logger() noexcept : sink_(&null_log_sink()) {}
  Logger(LogSink& sink, std::string component) : sink_(&sink), component_(std::move(component)) {}

  bool enabled(LogLevel level) const noexcept { return sink_->enabled(level); }
  const std::string& component() const noexcept { return component_; }
  LogSink& sink() const noexcept { return *sink_; }

  template <class... Args>
  void log(LogLevel level, fmt::format_string<Args...> format, Args&&... args) const {
    if (!sink_->enabled(level)) return;
    sink_->write(level, component_, fmt::format(format, std::forward<Args>(args)...));
  }
  template <class... Args>
  void trace(fmt::format_string<Args...> f, Args&&... a) const {
    log(LogLevel::kTrace, f, std::forward<Args>(a)...);
  }
  template <class... Args>
  void debug(fmt::format_string<Args...> f, Args&&... a) const {
    log(LogLevel::kDebug, f, std::forward<Args>(a)...);
  }
  template <class... Args>
  void info(fmt::format_string<Args...> f, Args&&... a) const {
    log(LogLevel::kInfo, f, std::forward<Args>(a)...);
  }
  template <class... Args>
  void warn(fmt::format_string<Args...> f, Args&&... a) const {
    log(LogLevel::kWarn, f, std::forward<Args>(a)...);
  }
  template <class... Args>
  void error(fmt::format_string<Args...> f, Args&&... a) const {
    log(LogLevel::kError, f, std::forward<Args>(a)...);
  }

 private:
  LogSink* sink_;
  std::string component_;
};

// Lets through at most `burst` messages per `window`; counts the rest so the
// next message that passes can say how many were suppressed.
class RateLimiter {
 public:
  explicit RateLimiter(Duration window = seconds(10), unsigned burst = 5) noexcept
      : window_(window), burst_(burst) {}

  // True if a message may be logged now. `suppressed` receives the number of
  // messages dropped since the last one that passed.
  bool allow(TimePoint now, unsigned& suppressed) noexcept {
    if (!started_ || now - window_start_ >= window_) {
      started_ = true;
      window_start_ = now;
      passed_ = 0;
    }
    if (passed_ >= burst_) {
      ++dropped_;
      return false;
    }
    ++passed_;
    suppressed = dropped_;
    dropped_ = 0;
    return true;
  }

 private:
  Duration window_;
  unsigned burst_;
  bool started_ = false;
  TimePoint window_start_{};
  unsigned passed_ = 0;
  unsigned dropped_ = 0;
};

}  // namespace dnbridge
