#pragma once
// Logging through an injected sink. The core formats a message only when the
// sink wants that level; anything on the frame path goes through a RateLimitedLog.
#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bridge/common/time.hpp"

namespace dnbridge {

enum class LogLevel : std::uint8_t { kTrace, kDebug, kInfo, kWarn, kError };

std::string_view to_string(LogLevel level) noexcept;

// A structured field of a log line, for sinks that keep them (the journal:
// `journalctl -u dnbridge@rack-A MAC=12`). Names as journald takes them:
// upper case letters, digits and underscores.
struct LogField {
  std::string_view name;
  std::string_view value;
};

class LogSink {
 public:
  virtual ~LogSink() = default;
  virtual bool enabled(LogLevel level) const noexcept = 0;
  virtual void write(LogLevel level, std::string_view component, std::string_view message) = 0;
  // With the fields of the logger that wrote it (what Logger calls); a sink
  // that keeps none writes the line alone.
  virtual void write_structured(LogLevel level, std::string_view component,
                                std::string_view message, std::span<const LogField> fields) {
    (void)fields;
    write(level, component, message);
  }
};

// A sink that drops everything.
LogSink& null_log_sink() noexcept;

// A component's handle on a sink: "port can0", "node 12", ..., with the
// structured fields every line it writes carries (RACK, PORT, MAC, ...).
class Logger {
 public:
  static constexpr std::size_t kMaxFields = 8;

  Logger() noexcept : sink_(&null_log_sink()) {}
  Logger(LogSink& sink, std::string component) : sink_(&sink), component_(std::move(component)) {}

  bool enabled(LogLevel level) const noexcept { return sink_->enabled(level); }
  const std::string& component() const noexcept { return component_; }
  LogSink& sink() const noexcept { return *sink_; }

  // This logger with one more field (replacing one of the same name), for
  // every line it writes. At most kMaxFields; more are not kept.
  Logger with(std::string_view name, std::string value) const {
    Logger l = *this;
    for (auto& [n, v] : l.fields_) {
      if (n == name) {
        v = std::move(value);
        return l;
      }
    }
    if (l.fields_.size() < kMaxFields) l.fields_.emplace_back(std::string(name), std::move(value));
    return l;
  }
  // The same logger (component, fields) writing to `sink` instead.
  Logger to(LogSink& sink) const {
    Logger l = *this;
    l.sink_ = &sink;
    return l;
  }
  // A logger of another component on the same sink, with these fields.
  Logger named(std::string component) const {
    Logger l = *this;
    l.component_ = std::move(component);
    return l;
  }

  template <class... Args>
  void log(LogLevel level, fmt::format_string<Args...> format, Args&&... args) const {
    if (!sink_->enabled(level)) return;
    std::array<LogField, kMaxFields> fields;
    for (std::size_t i = 0; i < fields_.size(); ++i)
      fields[i] = {fields_[i].first, fields_[i].second};
    sink_->write_structured(level, component_, fmt::format(format, std::forward<Args>(args)...),
                            std::span<const LogField>(fields.data(), fields_.size()));
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
  std::vector<std::pair<std::string, std::string>> fields_;
};

// A kind of message logged at most `burst` times per `window`: the rest are
// counted, and the next one that passes says how many were not logged
// ("... (12 more not logged)", or "(12 more refusals not logged)" with
// `what` = "refusals"). One per kind of message, held by whoever logs it.
class RateLimitedLog {
 public:
  explicit RateLimitedLog(Duration window = seconds(10), unsigned burst = 5,
                          std::string what = {}) noexcept
      : window_(window), burst_(burst), what_(std::move(what)) {}

  // Logs through `log` unless the limit is reached; true if it logged.
  template <class... Args>
  bool info(const Logger& log, TimePoint now, fmt::format_string<Args...> f, Args&&... a) {
    return write(log, LogLevel::kInfo, now, f, std::forward<Args>(a)...);
  }
  template <class... Args>
  bool warn(const Logger& log, TimePoint now, fmt::format_string<Args...> f, Args&&... a) {
    return write(log, LogLevel::kWarn, now, f, std::forward<Args>(a)...);
  }
  template <class... Args>
  bool error(const Logger& log, TimePoint now, fmt::format_string<Args...> f, Args&&... a) {
    return write(log, LogLevel::kError, now, f, std::forward<Args>(a)...);
  }

 private:
  template <class... Args>
  bool write(const Logger& log, LogLevel level, TimePoint now, fmt::format_string<Args...> f,
             Args&&... a) {
    unsigned dropped = 0;
    if (!allow(now, dropped)) return false;
    if (dropped == 0) {
      log.log(level, f, std::forward<Args>(a)...);
    } else {
      log.log(level, "{} ({} more{}{} not logged)", fmt::format(f, std::forward<Args>(a)...),
              dropped, what_.empty() ? "" : " ", what_);
    }
    return true;
  }

  bool allow(TimePoint now, unsigned& dropped) noexcept {
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
    dropped = dropped_;
    dropped_ = 0;
    return true;
  }

  Duration window_;
  unsigned burst_;
  std::string what_;
  bool started_ = false;
  TimePoint window_start_{};
  unsigned passed_ = 0;
  unsigned dropped_ = 0;
};

}  // namespace dnbridge
