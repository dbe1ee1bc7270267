#include "bridge/devicenet/master/io_connection.hpp"

#include "bridge/can/can_frame.hpp"

namespace dnbridge::devicenet {

IoFrame take_io_frame(IoReassembler& reassembler, Bytes payload, std::size_t size) {
  IoFrame f;
  if (size <= can::kMaxDataLength) {
    f.message = payload;
  } else {
    switch (reassembler.on_fragment(payload)) {
      case IoReassembler::Outcome::kIncomplete:
        f.outcome = IoFrame::kIncomplete;
        return f;
      case IoReassembler::Outcome::kComplete:
        f.message = reassembler.message();
        break;
      default:
        f.outcome = IoFrame::kOutOfOrder;
        f.got = static_cast<std::uint32_t>(payload.size());
        return f;
    }
  }
  f.got = static_cast<std::uint32_t>(f.message.size());
  f.outcome = f.message.size() == size ? IoFrame::kComplete : IoFrame::kWrongSize;
  return f;
}

}  // namespace dnbridge::devicenet
