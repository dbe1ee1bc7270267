#pragma once
// Log lines to standard error, one per line, safe from any thread:
//   2026-11-22T07:30:00.123Z info  port A node 3: online -> absent: ...
// Under systemd (JOURNAL_STREAM set) the time is left to the journal and each
// line carries its syslog priority instead ("<4>port A: ...").
#include <cstdio>
#include <mutex>

#include "bridge/common/log.hpp"

namespace dnbridge::daemon {

class StderrLogSink final : public LogSink {
 public:
  explicit StderrLogSink(LogLevel level, std::FILE* out = stderr);
  bool enabled(LogLevel level) const noexcept override { return level >= level_; }
  void write(LogLevel level, std::string_view component, std::string_view message) override;
  void set_level(LogLevel level) noexcept { level_ = level; }

 private:
  LogLevel level_;
  std::FILE* out_;
  bool journal_;
  std::mutex mutex_;
};

}  // namespace dnbridge::daemon
