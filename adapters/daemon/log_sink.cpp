#include "adapters/daemon/log_sink.hpp"

#include <fmt/format.h>
#include <sys/stat.h>
#include <sys/uio.h>
// The entries are the bridge's lines: no CODE_FILE/CODE_LINE of this sink.
#define SD_JOURNAL_SUPPRESS_LOCATION
#include <systemd/sd-journal.h>

#include <chrono>
#include <cstdlib>
#include <ctime>

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

// "2026-11-22T07:30:00.123Z": UTC to the millisecond.
std::string utc_now() {
  const auto now = std::chrono::system_clock::now();
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch());
  const std::time_t seconds = static_cast<std::time_t>(ms.count() / 1000);
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:03}Z", tm.tm_year + 1900, tm.tm_mon + 1,
                     tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, ms.count() % 1000);
}

}  // namespace

StderrLogSink::StderrLogSink(LogLevel level, std::FILE* out)
    : level_(level), out_(out), journal_(out == stderr ? journal_of_stderr() : JournalSend{}) {}

StderrLogSink::JournalSend StderrLogSink::journal_of_stderr() {
  // systemd sets JOURNAL_STREAM to the device and inode of the stream it
  // connected to the journal; standard error is the journal only if it is
  // still that stream (not redirected since).
  const char* stream = std::getenv("JOURNAL_STREAM");
  if (stream == nullptr) return {};
  unsigned long long dev = 0;
  unsigned long long ino = 0;
  if (std::sscanf(stream, "%llu:%llu", &dev, &ino) != 2) return {};
  struct stat st {};
  if (::fstat(2, &st) != 0 || st.st_dev != dev || st.st_ino != ino) return {};
  return [](std::span<const std::string> fields) {
    std::vector<iovec> iov;
    iov.reserve(fields.size());
    for (const auto& f : fields) {
      iov.push_back(
          {const_cast<char*>(f.data()), f.size()});  // NOLINT: sd_journal_sendv reads only
    }
    return sd_journal_sendv(iov.data(), static_cast<int>(iov.size()));
  };
}

void StderrLogSink::add_field(std::string name, std::string value) {
  std::lock_guard lock(mutex_);
  fields_.emplace_back(std::move(name), std::move(value));
}

void StderrLogSink::send_to_journal(JournalSend send) {
  std::lock_guard lock(mutex_);
  journal_ = std::move(send);
}

void StderrLogSink::write(LogLevel level, std::string_view component, std::string_view message) {
  write_structured(level, component, message, {});
}

void StderrLogSink::write_structured(LogLevel level, std::string_view component,
                                     std::string_view message, std::span<const LogField> fields) {
  std::lock_guard lock(mutex_);
  if (journal_) {
    std::vector<std::string> entry;
    entry.reserve(4 + fields_.size() + fields.size());
    entry.push_back(fmt::format("MESSAGE={}: {}", component, message));
    entry.push_back(fmt::format("PRIORITY={}", syslog_priority(level)));
    entry.push_back(fmt::format("COMPONENT={}", component));
    for (const auto& [name, value] : fields_) entry.push_back(fmt::format("{}={}", name, value));
    for (const auto& f : fields) entry.push_back(fmt::format("{}={}", f.name, f.value));
    if (journal_(entry) >= 0) return;
    const std::string line =
        fmt::format("<{}>{}: {}\n", syslog_priority(level), component, message);
    std::fwrite(line.data(), 1, line.size(), out_);
    std::fflush(out_);
    return;
  }
  const std::string line =
      fmt::format("{} {:<5} {}: {}\n", utc_now(), to_string(level), component, message);
  std::fwrite(line.data(), 1, line.size(), out_);
  std::fflush(out_);
}

}  // namespace dnbridge::daemon
