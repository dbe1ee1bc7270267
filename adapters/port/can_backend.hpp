#pragma once
// Where a port's frames come from and go to: the in-process simulated bus, or
// a SocketCAN interface. Used from the port's own thread only, except wake().
#include <cstdint>
#include <string>
#include <string_view>

#include "adapters/port/candump_log.hpp"
#include "bridge/can/can_frame.hpp"
#include "bridge/can/frame_sink.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::port {

class FrameReceiver {
 public:
  virtual ~FrameReceiver() = default;
  virtual void on_frame(const can::CanFrame& frame, TimePoint rx_time) = 0;
};

// CAN controller state, as the interface reports it.
enum class BusState : std::uint8_t {
  kErrorActive,
  kErrorWarning,
  kErrorPassive,
  kBusOff,
  kUnknown,
  kDown  // the interface is down or absent: nothing goes out or comes in
};

// "error-active", "bus-off", "interface down", ...: the one name of each
// state, in the logs, on dnbctl and in its JSON.
constexpr std::string_view to_string(BusState s) noexcept {
  switch (s) {
    case BusState::kErrorActive:
      return "error-active";
    case BusState::kErrorWarning:
      return "error-warning";
    case BusState::kErrorPassive:
      return "error-passive";
    case BusState::kBusOff:
      return "bus-off";
    case BusState::kUnknown:
      return "unknown";
    case BusState::kDown:
      return "interface down";
  }
  return "?";
}

// Nothing goes out or comes in: bus-off, or the interface down.
constexpr bool bus_lost(BusState s) noexcept {
  return s == BusState::kBusOff || s == BusState::kDown;
}

struct BusCounters {
  BusState state = BusState::kUnknown;
  std::uint16_t tx_errors = 0;  // transmit error counter
  std::uint16_t rx_errors = 0;  // receive error counter
  std::uint64_t frames = 0;     // frames seen on the bus, both ways
  std::uint64_t bits = 0;       // their length on the wire, stuffing included
  // Times the bus was lost (bus_lost) since the backend was made: a loss
  // and its recovery between two looks at `state` still show here.
  std::uint64_t losses = 0;
};

class CanBackend {
 public:
  virtual ~CanBackend() = default;

  virtual can::FrameSink& sink() = 0;
  // The backend's monotonic time: the clock its receive times are on.
  virtual TimePoint now() const = 0;
  // Hands received frames to `receiver` and returns when at least one was
  // handled, `deadline` has come, or wake() was called.
  virtual void wait(TimePoint deadline, FrameReceiver& receiver) = 0;
  // Makes a wait() in progress (or the next one) return at once. Any thread.
  virtual void wake() = 0;

  virtual BusCounters counters() const = 0;
  virtual std::string interface_name() const = 0;  // "can0", "simulated"
  virtual std::uint32_t bitrate() const = 0;
  // What is wrong with the interface, for operators ("vcan0 down: ..."); empty
  // when nothing is.
  virtual std::string problem() const { return {}; }

  // The candump -l log of the port's traffic (SIGUSR1), started and stopped
  // by whoever runs the port; every backend writes into it what it sends and
  // receives, error frames included. The port's thread only.
  CandumpLog& candump() noexcept { return candump_; }

 protected:
  CandumpLog candump_;
};

}  // namespace dnbridge::port
