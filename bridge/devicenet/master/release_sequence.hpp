#pragma once
// What the master holds of a node, released when it leaves the node (a
// fault, a loss, an orderly shutdown): everything in one Release. A device
// that lacks one of the connections named refuses that Release whole (0x0B,
// PROTOCOL.md §3) and keeps the others; they are then released one at a
// time, whatever each answer, the I/O connections first and the explicit
// connection last.
#include <cstdint>

#include "bridge/devicenet/wire/explicit_message.hpp"

namespace dnbridge::devicenet {

class ReleaseSequence {
 public:
  // A Release of everything held is sent: nothing is left of an earlier one.
  void begin() { left_ = 0; }

  // The answer to the Release of `asked` (allocation choice bits), refused
  // whole with 0x0B or not: the connection to release next, or 0 once none
  // is left.
  std::uint8_t after(std::uint8_t asked, bool refused_whole) {
    auto left = static_cast<std::uint8_t>(left_ & ~asked);
    const bool several = (asked & (asked - 1)) != 0;
    if (left_ == 0 && refused_whole && several) left = asked;
    left_ = left;
    if (left == 0) return 0;
    // Its lowest bit but the explicit connection's, while there is another.
    const auto io = static_cast<std::uint8_t>(left & ~allocation::kExplicit);
    return static_cast<std::uint8_t>(io != 0 ? io & -io : left);
  }

 private:
  // In a sequence: the connections still to release, the one in hand
  // included; 0 otherwise.
  std::uint8_t left_ = 0;
};

}  // namespace dnbridge::devicenet
