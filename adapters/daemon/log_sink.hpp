#pragma once
// Log lines to standard error, one per line, safe from any thread:
//   2026-11-22T07:30:00.123Z info  port A node 3: online -> absent: ...
// Under systemd, when standard error is the journal (JOURNAL_STREAM names
// it), each line goes to the journal as an entry of its own, with its
// priority and its structured fields (RACK, PORT, MAC, NODE, NODE_STATE, ...),
// so that `journalctl -u dnbridge@rack-A MAC=12` finds a node's lines; the
// journal keeps the time. Should the journal refuse an entry, the line goes
// to standard error with its syslog priority ("<4>port A: ...").
#include <atomic>
#include <cstdio>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bridge/common/log.hpp"

namespace dnbridge::daemon {

class StderrLogSink final : public LogSink {
 public:
  // Sends one journal entry, its fields as "NAME=value"; returns 0 or a
  // negative errno (sd_journal_sendv's contract).
  using JournalSend = std::function<int(std::span<const std::string> fields)>;

  explicit StderrLogSink(LogLevel level, std::FILE* out = stderr);
  bool enabled(LogLevel level) const noexcept override {
    return level >= level_.load(std::memory_order_relaxed);
  }
  void write(LogLevel level, std::string_view component, std::string_view message) override;
  void write_structured(LogLevel level, std::string_view component, std::string_view message,
                        std::span<const LogField> fields) override;
  // Any thread (a reload changes it while the ports log).
  void set_level(LogLevel level) noexcept { level_.store(level, std::memory_order_relaxed); }

  // A field every entry carries (the rack's name, RACK). Before logging starts.
  void add_field(std::string name, std::string value);
  // Entries to `send` (the journal's, or a test's) rather than to `out`.
  void send_to_journal(JournalSend send);
  bool to_journal() const noexcept { return static_cast<bool>(journal_); }

  // sd_journal_sendv, when JOURNAL_STREAM says standard error is the journal;
  // empty otherwise.
  static JournalSend journal_of_stderr();

 private:
  std::atomic<LogLevel> level_;
  std::FILE* out_;
  JournalSend journal_;
  std::vector<std::pair<std::string, std::string>> fields_;
  std::mutex mutex_;
};

}  // namespace dnbridge::daemon
