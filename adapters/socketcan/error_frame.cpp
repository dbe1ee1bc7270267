#include "adapters/socketcan/error_frame.hpp"

#include <fmt/format.h>
#include <linux/can/error.h>

namespace dnbridge::socketcan {

using port::BusState;

ErrorFrameReport decode_error_frame(std::uint32_t error_class,
                                    const std::array<std::uint8_t, 8>& data) noexcept {
  ErrorFrameReport r;
  if (error_class & CAN_ERR_CRTL) {
    const std::uint8_t c = data[1];
    // The worst condition named wins: one frame may report RX warning and TX
    // passive at once.
    if (c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) {
      r.state = BusState::kErrorPassive;
    } else if (c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) {
      r.state = BusState::kErrorWarning;
    } else if (c & CAN_ERR_CRTL_ACTIVE) {
      r.state = BusState::kErrorActive;
    }
    r.rx_overflow = (c & CAN_ERR_CRTL_RX_OVERFLOW) != 0;
    r.tx_overflow = (c & CAN_ERR_CRTL_TX_OVERFLOW) != 0;
  }
  if (error_class & CAN_ERR_RESTARTED) {
    r.restarted = true;
    r.state = BusState::kErrorActive;  // a restarted controller starts error-active
  }
  if (error_class & CAN_ERR_BUSOFF) {
    r.bus_off = true;
    r.state = BusState::kBusOff;
  }
  // Drivers have long filled data[6]/[7] with the counters on controller
  // frames; CAN_ERR_CNT (Linux 6.1) says so explicitly.
  if (error_class & (CAN_ERR_CNT | CAN_ERR_CRTL)) {
    r.tx_errors = data[6];
    r.rx_errors = data[7];
  }
  r.tx_timeout = (error_class & CAN_ERR_TX_TIMEOUT) != 0;
  r.no_ack = (error_class & CAN_ERR_ACK) != 0;
  r.protocol = (error_class & CAN_ERR_PROT) != 0;
  r.transceiver = (error_class & CAN_ERR_TRX) != 0;
  return r;
}

std::string describe(const ErrorFrameReport& r) {
  std::string s;
  auto add = [&s](std::string_view part) {
    if (!s.empty()) s += ", ";
    s += part;
  };
  if (r.state) add(to_string(*r.state));
  if (r.restarted) add("controller restarted");
  if (r.tx_errors || r.rx_errors) {
    add(fmt::format("tx errors {}, rx errors {}", r.tx_errors.value_or(0),
                    r.rx_errors.value_or(0)));
  }
  if (r.no_ack) add("no ACK");
  if (r.tx_timeout) add("transmit timeout");
  if (r.protocol) add("protocol violation");
  if (r.transceiver) add("transceiver fault");
  if (r.rx_overflow) add("receive overflow");
  if (r.tx_overflow) add("transmit overflow");
  if (s.empty()) s = "unclassified error frame";
  return s;
}

}  // namespace dnbridge::socketcan
