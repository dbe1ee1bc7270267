#pragma once
// The bridge that (1), (2) and (3) measure: daemon::Daemon in this process,
// its configuration built here, each port on a ThreadedSimBackend (the
// simulated bus and devices on a thread of their own), with a tap on each
// port's bus and, for (2), on what its master writes and is handed.
#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "adapters/daemon/daemon.hpp"
#include "adapters/sim/world/threaded_sim_backend.hpp"
#include "bridge/can/can_timing.hpp"
#include "bridge/common/log.hpp"
#include "bridge/common/time.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::bench {

struct BridgeSetup {
  std::vector<std::string> ports;
  unsigned nodes = 0;
  std::uint32_t bitrate = can::kBitrate500k;
  Duration poll_period = milliseconds(10);
  rack::PublishPolicy publish;
  bool ramp = false;            // a new analog input value before every poll
  bool record_outputs = false;  // the first poll frame of each new output value
};

// The first poll frame of a new output value on the wire.
struct OutputFrame {
  unsigned mac;
  unsigned value;
  std::int64_t start;  // on the wire: start and end of frame, steady clock
  std::int64_t end;
};

// The same frame as its master wrote it.
struct WrittenFrame {
  unsigned mac;
  unsigned value;
  std::int64_t at;  // written to the CAN interface by the master, steady clock
  // Written while the master was handling the node's poll response: the
  // outputs waited for the poll in flight (a poll connection carries one
  // poll at a time).
  bool after_response;
  std::int64_t response_rx;  // then: that response's receive time, steady clock
  // The port's thread's last wait before it wrote the frame: when it
  // began, and when the thread ran again after it, steady clock.
  std::int64_t waited_since;
  std::int64_t woke;
  // The last wake() of the port's loop before the thread ran again (an
  // item posted to its inbox, here by the bridge's command listener on
  // Cyclone's thread), steady clock; 0 if none during that wait.
  std::int64_t woken_by;
};

// What one port's taps see (bridge_bench_bridge.cpp).
struct PortWire;

class Bridge {
 public:
  Bridge(const BridgeSetup& s, int domain, LogSink& log);
  ~Bridge();
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;

  void start();
  void stop();

  // The simulated worlds' threads, together.
  std::int64_t sim_cpu_ns() const;
  std::uint64_t polls() const;
  std::uint64_t responses() const;
  std::uint64_t bus_bits() const;
  // The threads of the ports' loops and of the simulated worlds.
  std::set<pid_t> port_threads();
  std::set<pid_t> sim_threads();

  // With BridgeSetup::record_outputs, every port's, in port order.
  std::vector<OutputFrame> output_frames();
  std::vector<WrittenFrame> written_frames();
  // Every poll response handed to a port's thread: its key and analog
  // value, from its receive time to the thread having it (ns), and whether
  // that was the thread's wake-up for it (the thread was waiting when the
  // response was received, and it was the first frame handed to it).
  // Once the bridge has stopped.
  struct Handed {
    std::size_t key;
    unsigned value;
    std::int64_t ns;
    bool slept;
  };
  std::vector<Handed> handed_responses();

 private:
  // Port `p`'s backend, its taps set.
  std::unique_ptr<port::CanBackend> make_backend(const BridgeSetup& s, const daemon::PortConfig& p,
                                                 const profiles::cdn127::PollFormat& format,
                                                 LogSink& log);

  std::vector<sim::ThreadedSimBackend*> backends_;
  std::vector<std::unique_ptr<PortWire>> wires_;  // outlive the daemon (its backends' taps)
  std::unique_ptr<daemon::Daemon> daemon_;
};

}  // namespace dnbridge::bench
