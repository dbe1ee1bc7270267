#include "bridge/common/log.hpp"

namespace dnbridge {

std::string_view to_string(LogLevel level) noexcept {
  switch (level) {
    case LogLevel::kTrace:
      return "trace";
    case LogLevel::kDebug:
      return "debug";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kWarn:
      return "warn";
    case LogLevel::kError:
      return "error";
  }
  return "?";
}

namespace {
class NullSink final : public LogSink {
 public:
  bool enabled(LogLevel) const noexcept override { return false; }
  void write(LogLevel, std::string_view, std::string_view) override {}
};
}  // namespace

LogSink& null_log_sink() noexcept {
  static NullSink sink;
  return sink;
}

}  // namespace dnbridge
