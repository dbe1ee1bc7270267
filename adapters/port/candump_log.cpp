#include "adapters/port/candump_log.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <system_error>

namespace dnbridge::port {

Status CandumpLog::start(const std::string& path, std::string interface) {
  std::FILE* f = std::fopen(path.c_str(), "a");
  if (f == nullptr) return std::error_code(errno, std::system_category());
  file_.reset(f);
  path_ = path;
  interface_ = std::move(interface);
  return {};
}

std::chrono::nanoseconds CandumpLog::wall_now() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::system_clock::now().time_since_epoch());
}

void CandumpLog::frame(const can::CanFrame& frame, std::chrono::nanoseconds wall) {
  if (!file_) return;
  // A standard identifier in three hex digits.
  line(wall, fmt::format("{:03X}", frame.id), frame.data.data(), frame.len);
}

void CandumpLog::error_frame(std::uint32_t id, const std::array<std::uint8_t, 8>& data,
                             std::chrono::nanoseconds wall) {
  if (!file_) return;
  // Eight hex digits: CAN_ERR_FLAG (0x20000000) and the class bits
  // (CAN_ERR_MASK), as candump prints an error frame.
  line(wall, fmt::format("{:08X}", id & 0x3FFFFFFFu), data.data(), data.size());
}

void CandumpLog::line(std::chrono::nanoseconds wall, const std::string& id,
                      const std::uint8_t* data, std::size_t len) {
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(wall).count();
  std::string bytes;
  for (std::size_t i = 0; i < len; ++i) bytes += fmt::format("{:02X}", data[i]);
  fmt::print(file_.get(), "({}.{:06}) {} {}#{}\n", us / 1'000'000, us % 1'000'000, interface_, id,
             bytes);
}

}  // namespace dnbridge::port
