#include "adapters/daemon/log_sink.hpp"

#include <fmt/chrono.h>
#include <fmt/format.h>

#include <chrono>
#include <cstdlib>

namespace dnbridge::daemon {
namespace {

int syslog_priority(LogLevel level) {
  switch (level) {
    case LogLevel::kTrace:
    case LogLevel::kDebug:
      return 7;
    case LogLevel::kInfo:
      return 6;
    case LogLevel::kWarn:
      return 4;
    case LogLevel::kError:
      return 3;
  }
  return 6;
}

}  // namespace

StderrLogSink::StderrLogSink(LogLevel level, std::FILE* out)
    : level_(level), out_(out), journal_(std::getenv("JOURNAL_STREAM") != nullptr) {}

void StderrLogSink::write(LogLevel level, std::string_view component, std::string_view message) {
  std::string line;
  if (journal_) {
    line = fmt::format("<{}>{}: {}\n", syslog_priority(level), component, message);
  } else {
    const auto now =
        std::chrono::time_point_cast<std::chrono::milliseconds>(std::chrono::system_clock::now());
    line = fmt::format("{:%Y-%m-%dT%H:%M:%S}Z {:<5} {}: {}\n", now, to_string(level), component,
                       message);
  }
  std::lock_guard lock(mutex_);
  std::fwrite(line.data(), 1, line.size(), out_);
  std::fflush(out_);
}

}  // namespace dnbridge::daemon
