#pragma once
// Where a protocol state machine hands the frames it wants sent. The adapter
// behind it (SocketCAN, the simulated bus, a test) queues them; send() never
// calls back into the state machine.
#include "bridge/can/can_frame.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::can {

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // `now` is the time of the event being handled when the frame was produced.
  virtual void send(const CanFrame& frame, TimePoint now) = 0;
};

}  // namespace dnbridge::can
