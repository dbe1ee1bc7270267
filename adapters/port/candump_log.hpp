#pragma once
// A port's traffic as `candump -l` writes it, for field diagnosis: SIGUSR1
// starts it in every port (and the next stops it), whatever the backend, the
// simulated bus included. One line a frame, both ways:
//   (1700000000.123456) can0 3C5#0102
// and an error frame with its identifier's flags, as candump shows it:
//   (1700000000.123456) can0 20000004#0000080000000000
// The port's thread only.
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "bridge/can/can_frame.hpp"
#include "bridge/common/result.hpp"

namespace dnbridge::port {

class CandumpLog {
 public:
  // Appends to `path` from now on, naming the interface `interface`.
  Status start(const std::string& path, std::string interface);
  void stop() noexcept { file_.reset(); }
  bool active() const noexcept { return file_ != nullptr; }
  const std::string& path() const noexcept { return path_; }

  // `wall`: the frame's time since the epoch (CLOCK_REALTIME), as candump
  // logs it. Nothing happens unless active().
  void frame(const can::CanFrame& frame, std::chrono::nanoseconds wall);
  // `id`: the error frame's identifier, CAN_ERR_FLAG and class bits included.
  void error_frame(std::uint32_t id, const std::array<std::uint8_t, 8>& data,
                   std::chrono::nanoseconds wall);

  // Now on CLOCK_REALTIME, for backends whose frames carry no wall time.
  static std::chrono::nanoseconds wall_now() noexcept;

 private:
  struct Closer {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
  };
  void line(std::chrono::nanoseconds wall, const std::string& id, const std::uint8_t* data,
            std::size_t len);

  std::unique_ptr<std::FILE, Closer> file_;
  std::string path_;
  std::string interface_;
};

}  // namespace dnbridge::port
