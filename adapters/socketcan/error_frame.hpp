#pragma once
// What a SocketCAN error frame says about the bus (linux/can/error.h): the
// controller's error state, its error counters, and the events worth a log
// line. Pure: the caller keeps the state.
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "adapters/port/can_backend.hpp"

namespace dnbridge::socketcan {

struct ErrorFrameReport {
  // The controller state the frame announces, if it announces one.
  std::optional<port::BusState> state;
  // Transmit and receive error counters, when the frame carries them.
  std::optional<std::uint8_t> tx_errors;
  std::optional<std::uint8_t> rx_errors;
  bool bus_off = false;
  bool restarted = false;  // the controller was restarted (after bus-off)
  bool tx_timeout = false;
  bool no_ack = false;       // transmitted, nobody acknowledged (alone on the bus?)
  bool protocol = false;     // a protocol violation (bit, stuff, form, ...)
  bool transceiver = false;  // a transceiver fault (wiring)
  bool rx_overflow = false;  // the controller lost received frames
  bool tx_overflow = false;
};

// `error_class` is the identifier's CAN_ERR_* bits (flag removed), `data`
// the frame's eight bytes.
ErrorFrameReport decode_error_frame(std::uint32_t error_class,
                                    const std::array<std::uint8_t, 8>& data) noexcept;

// "bus-off", "error-passive (tx 128, rx 0), no ACK", ... for logs.
std::string describe(const ErrorFrameReport& report);

}  // namespace dnbridge::socketcan
