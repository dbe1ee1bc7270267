#pragma once
// What answers at MACs the scan list does not have (a bus scan). For each
// MAC: Allocate of the explicit connection on the Group 2 unconnected port,
// Gets of the Identity object, Release of what was allocated. Each MAC is
// asked once per probe, nothing is retried, and at most kSlots MACs are
// asked at a time: a silent MAC costs one frame. A node that
// refuses the Allocate (another master holds it) is left alone; so is one
// the master heard answering another master's polls, which is not asked.
//
// Sans-IO, driven by the Scanner (scanner.hpp): frames on Group 2 message 3
// from a probed MAC come in through on_frame(), time through on_timer().
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "bridge/can/frame_sink.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/explicit_client.hpp"
#include "bridge/devicenet/master/scanner_events.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::devicenet {

class BusProbe {
 public:
  // MACs asked at once.
  static constexpr std::size_t kSlots = 8;

  struct Config {
    // A MAC silent for this long after the Allocate is taken for empty.
    Duration allocate_timeout = milliseconds(1000);
    // The answer to each later request (Gets, Release), of a node that
    // answered: longer than the 1 s a slave waits before it sends an
    // unacknowledged response fragment again.
    Duration response_timeout = milliseconds(2000);
  };

  // `probe`: the MACs to ask, in that order; `answering_other_master`: MACs
  // reported as such without being asked.
  BusProbe(MacId master, std::vector<MacId> probe, const std::vector<MacId>& answering_other_master,
           Config config, can::FrameSink& sink);
  ~BusProbe();
  BusProbe(const BusProbe&) = delete;
  BusProbe& operator=(const BusProbe&) = delete;

  void start(TimePoint now);
  // A frame on Group 2 message 3 from `mac`: false when `mac` is not being
  // asked now (the frame is someone else's).
  bool on_frame(MacId mac, Bytes payload, TimePoint now);
  // Call when now >= deadline().
  void on_timer(TimePoint now);
  TimePoint deadline() const;
  bool done() const;
  // Ends at once: MACs not finished are reported as not asked (`why`).
  void cancel(std::string_view why, TimePoint now);
  // What was found, in MAC order, once done().
  const std::vector<ScanFinding>& findings() const { return findings_; }

 private:
  class Slot;
  void fill_slots(TimePoint now);
  void finished(ScanFinding finding);

  MacId master_;
  std::vector<MacId> waiting_;  // not yet asked, in reverse order
  Config config_;
  can::FrameSink& sink_;
  std::vector<std::unique_ptr<Slot>> slots_;
  std::vector<ScanFinding> findings_;
};

}  // namespace dnbridge::devicenet
