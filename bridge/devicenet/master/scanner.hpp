#pragma once
// The DeviceNet master of one CAN port: checks its own MAC, then drives every
// scan-list node (node.hpp) and routes received frames to them.
//
// Sans-IO: the port's event loop calls on_frame() for every received frame,
// on_timer() when next_deadline() has come, and the request methods on behalf
// of the layer above. Frames go out through the FrameSink, events through the
// ScannerObserver.
#include <array>
#include <bitset>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bridge/can/can_frame.hpp"
#include "bridge/can/frame_sink.hpp"
#include "bridge/common/log.hpp"
#include "bridge/common/result.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/bus_probe.hpp"
#include "bridge/devicenet/master/node.hpp"
#include "bridge/devicenet/master/scan_list.hpp"
#include "bridge/devicenet/master/scanner_events.hpp"
#include "bridge/devicenet/wire/duplicate_mac.hpp"

namespace dnbridge::devicenet {

struct PortCounters {
  std::uint64_t frames_received = 0;
  std::uint64_t invalid_identifiers = 0;  // outside the DeviceNet groups
  std::uint64_t foreign_frames = 0;       // valid, but not for this master
  std::uint64_t unknown_nodes = 0;        // from a MAC not in the scan list
  std::uint64_t bit_strobes = 0;          // bit-strobe commands sent
};

class Scanner {
 public:
  // Throws std::invalid_argument for a scan list that cannot work (duplicate
  // or out-of-range MACs, the master's MAC in it, periods of zero, EPR shorter
  // than the poll period, a poll message over Node::kMaxIoSize, a negative
  // immediate poll gap).
  Scanner(ScannerConfig config, can::FrameSink& sink, ScannerObserver& observer, Logger log);
  Scanner(const Scanner&) = delete;
  // The constructor's check of a scan list, alone (a configuration read
  // again is checked whole before anything of it is applied).
  static void check(const ScannerConfig& config);
  Scanner& operator=(const Scanner&) = delete;

  // Starts the duplicate MAC ID check; scanning follows when it passes.
  void start(TimePoint now);
  // Orderly shutdown: idle polls and Release for every node; stopped() when done.
  void stop(TimePoint now);
  // The bus came back (bus-off recovered, the interface up again): every node
  // is taken as lost, and the master checks its own MAC again before it
  // scans (a node must not talk on a bus it rejoins before that check).
  // While running, or during a check (which starts again).
  void recheck_mac(std::string_view why, TimePoint now);

  void on_frame(const can::CanFrame& frame, TimePoint rx_time);
  void on_timer(TimePoint now);
  TimePoint next_deadline() const;

  Status set_outputs(MacId mac, Bytes data, TimePoint now);
  Status set_idle(MacId mac, bool idle, TimePoint now);
  // Queues an explicit request to a node; returns its id, which the result
  // carries. kNotConnected when the node holds no connection, kBusy when its
  // queue is full, kOutOfRange for a MAC not in the scan list.
  Result<std::uint32_t> request_explicit(MacId mac, const RequestMessage& request, TimePoint now);
  // Starts a bus scan (bus_probe.hpp) of every MAC but the master's and the
  // scan list's; on_bus_scan() tells its end. kStopped unless the port is
  // running, kBusy while a scan is under way. The scan list's nodes are
  // never addressed; MACs heard answering another master's polls are not
  // asked.
  Status scan_bus(TimePoint now);
  bool scanning_bus() const { return probe_ != nullptr; }

  // Live changes (a configuration read again). A node not named is not
  // touched: it keeps its connections and its poll slot. A bus scan under
  // way ends early when the scan list changes.
  //
  // The port's timings: every ScannerConfig field but the master's MAC, its
  // duplicate MAC ID identity (vendor, serial number, window) and the
  // nodes. retune() takes them from `next` for every node at once.
  static bool same_timings(const ScannerConfig& a, const ScannerConfig& b);
  void retune(const ScannerConfig& next);
  // Adds a node: it starts at once while the port scans or, when its MAC is
  // still being released (remove_node), once that is done. Throws
  // std::invalid_argument for a node the scan list cannot take (as the
  // constructor); kStopped while the port stops.
  Status add_node(NodeConfig node, TimePoint now);
  // Takes a node out of the scan list at once: no outputs, idle or requests
  // are taken for it any more. While the port scans it gets one idle poll
  // and is released, as at shutdown; frames from its MAC reach it until
  // then. kOutOfRange for a MAC not in the scan list, kStopped while the
  // port stops.
  Status remove_node(MacId mac, TimePoint now);
  // Nodes taken out of the scan list and not yet released; whether one is
  // at `mac`.
  std::size_t nodes_leaving() const { return leaving_.size(); }
  bool leaving(MacId mac) const;

  PortState state() const { return state_; }
  const std::string& reason() const { return reason_; }
  bool stopped() const;
  // The scan list's node at `mac`; null for a MAC it does not have.
  const Node* node(MacId mac) const;
  const std::vector<std::unique_ptr<Node>>& nodes() const { return nodes_; }
  const PortCounters& counters() const { return counters_; }
  // MACs heard on the bus (a duplicate MAC ID check, a response to another
  // master) that the scan list does not have, within kUnconfiguredMemory
  // before `now`: a node whose MAC switch is set wrong, or one not yet
  // configured. Each is logged when first heard, and again when heard after
  // it was forgotten.
  static constexpr Duration kUnconfiguredMemory = seconds(600);
  std::bitset<MacId::kMax + 1> unconfigured_heard(TimePoint now) const;
  // The port's settings; the scan list is nodes() (config().nodes is what
  // the scanner was built with).
  const ScannerConfig& config() const { return config_; }

 private:
  void set_state(PortState next, std::string reason, TimePoint now);
  void begin_scanning(TimePoint now);
  void dispatch(const can::CanFrame& frame, TimePoint rx_time);
  void finish_stopping(TimePoint now);
  Node* find(MacId mac);
  // Where a frame from `mac` goes: a node being released, or the scan list's.
  Node* route(MacId mac);
  Node& make_node(NodeConfig config);
  // Nodes released after remove_node() go; a node added at the same MAC
  // starts then.
  void reap(TimePoint now);
  // Leaving nodes dropped without a word (the port halted: another node has
  // the master's MAC, or it stopped before it was back on the bus).
  void drop_leaving(std::string_view reason, TimePoint now);
  // A frame from `mac`, which is not in the scan list and not the master's.
  void heard_unconfigured(MacId mac, std::string_view how, TimePoint at);
  // The port's bit-strobe command (Group 2 message 0, 8 bytes, one bit per
  // MAC): every strobe_period() while a node has its bit-strobe connection
  // (Node::strobed()); the period is the shortest poll period of the scan
  // list's bit-strobe nodes (zero: none). schedule_strobes() sets the next
  // slot when the port starts scanning and when the scan list changes.
  static constexpr std::uint8_t kBitStrobeCommandSize = 8;
  Duration strobe_period() const;
  void strobe(TimePoint now);
  void schedule_strobes(TimePoint now);
  // A bit-strobe response from a MAC the scan list does not have.
  static constexpr Duration kStrayStrobeReleaseInterval = seconds(10);
  void stray_strobe_response(MacId mac, TimePoint at);
  // Ends the bus scan under way, if any, and reports it; `why` (not empty)
  // when it ends early.
  void end_bus_scan(std::string_view why, TimePoint now);

  ScannerConfig config_;
  can::FrameSink& sink_;
  ScannerObserver& observer_;
  Logger log_;
  std::vector<std::unique_ptr<Node>> nodes_;
  std::array<Node*, MacId::kMax + 1> by_mac_{};
  std::vector<std::unique_ptr<Node>> leaving_;  // removed, being idled and released
  DuplicateMacCheck mac_check_;
  PortState state_ = PortState::kStopped;
  std::string reason_ = "not started";
  std::uint32_t next_request_id_ = 1;
  PortCounters counters_;
  std::array<TimePoint, MacId::kMax + 1> unconfigured_last_heard_;  // kNever: not heard
  // Of those, the ones heard answering another master's polls since they
  // were last heard powering up.
  std::bitset<MacId::kMax + 1> answering_other_master_;
  std::unique_ptr<BusProbe> probe_;
  TimePoint probe_started_{};
  RateLimitedLog foreign_log_limit_;
  TimePoint next_strobe_ = kNever;
  TimePoint strobe_slot_ = kNever;                               // the last slot served
  TimePoint last_strobe_sent_ = kNever;                          // the last command sent
  std::array<TimePoint, MacId::kMax + 1> stray_strobe_release_;  // kNever: none sent
};

}  // namespace dnbridge::devicenet
