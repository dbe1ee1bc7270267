#pragma once
// One CAN port's event loop, on a thread of its own. It owns the port's
// DeviceNet master (Scanner), the rack model of its nodes (every profile's:
// rack::RackPort), the explicit gateway and the CAN backend; nothing else
// touches them. Other threads (the DDS input) talk to it through its inbox,
// which wakes it. Each pass runs the master's timers, the inbox, the
// command refresh, then the components that publish (NodePublication,
// PortStatusSchedule with BusMetrics), answer bus scans (BusScans) and apply
// a reload (PortReconfiguration); it then waits for a frame, a wake, or the
// earliest time any of them says it next needs to run.
#include <array>
#include <atomic>
#include <bit>
#include <bitset>
#include <chrono>
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <variant>
#include <vector>

#include "adapters/port/bus_metrics.hpp"
#include "adapters/port/bus_scans.hpp"
#include "adapters/port/can_backend.hpp"
#include "adapters/port/node_publication.hpp"
#include "adapters/port/port_config.hpp"
#include "adapters/port/port_publisher.hpp"
#include "adapters/port/port_reconfiguration.hpp"
#include "adapters/port/port_status_schedule.hpp"
#include "bridge/common/log.hpp"
#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/rack/explicit_gateway.hpp"
#include "bridge/rack/publish_gate.hpp"
#include "bridge/rack/rack_port.hpp"

namespace dnbridge::port {

class PortLoop final : private devicenet::ScannerObserver, private FrameReceiver {
 public:
  // Throws std::invalid_argument for a configuration the master refuses.
  PortLoop(PortLoopConfig config, std::unique_ptr<CanBackend> backend, PortPublisher& publisher,
           LogSink& log);
  ~PortLoop() override;
  PortLoop(const PortLoop&) = delete;
  PortLoop& operator=(const PortLoop&) = delete;

  void start();
  // Orderly stop: every node idle, then released; then the port's instances
  // are unregistered. Returns at once; join() waits.
  void stop();
  void join();

  // From any thread: queued for the port's thread, which is woken. New
  // outputs for the node at `mac`, in a form its profile takes
  // (rack::ProfileNodes::command).
  void command(devicenet::MacId mac, rack::NodeCommand command, std::string issuer);
  // No live commander left for the node at `mac`.
  void release_command(devicenet::MacId mac);
  // Past kMaxQueuedCalls requests waiting for the loop, answered at once
  // with "out of buffers" (on the caller's thread, through the publisher).
  void explicit_request(rack::ExplicitCall call);
  static constexpr std::size_t kMaxQueuedCalls = 256;
  // Requests handled in one pass of the loop; the rest wait for the next
  // pass, which comes at once, after the bus's timers and frames.
  static constexpr std::size_t kCallsPerPass = 32;
  // A bus scan (devicenet::Scanner::scan_bus), answered through the
  // publisher when it ends. One scan at a time: a request while one runs
  // waits for it (at most kMaxScanWaiters, the rest answered at once with
  // "out of buffers"); one within kScanHoldoff after a complete scan gets
  // that scan again, so that requests cannot make the bus scanned more
  // often (bus_scans.hpp).
  void scan_request(ScanCall call);
  static constexpr std::size_t kMaxScanWaiters = BusScans::kMaxWaiters;
  static constexpr Duration kScanHoldoff = BusScans::kHoldoff;
  // A configuration read again (a reload): the port's scan list, its
  // timings, its nodes' publish policies and the explicit policy, applied
  // on the port's thread at its next pass, only where they differ
  // (rack::RackPort::reconfigure); nodes not changed keep polling,
  // untouched. The port's name, interface and master stay as they are
  // (they need a restart). Removed nodes' instances are disposed. The
  // future says what changed; it is never fulfilled once the loop stopped.
  std::future<PortChange> reconfigure(PortLoopConfig next);
  // Runs `fn` on the port's thread with its backend (tests and tools only).
  void post(std::function<void(CanBackend&)> fn);

  const std::string& name() const { return config_.port; }
  // Whether `mac` is in the port's scan list; the profile of the node at
  // `mac` ("cdn127", "eds"), empty when none (any thread).
  bool has_node(devicenet::MacId mac) const {
    return (scan_list_.load(std::memory_order_relaxed) >> mac.value()) & 1u;
  }
  std::string_view profile_of(devicenet::MacId mac) const {
    const std::uint8_t p = profile_of_[mac.value()].load(std::memory_order_acquire);
    return p == 0 ? std::string_view{} : profile_names_[p - 1];
  }
  // The node's command_refresh_ms, 0 when off or not a node (any thread).
  std::uint32_t command_refresh_ms(devicenet::MacId mac) const {
    return refresh_ms_[mac.value()].load(std::memory_order_relaxed);
  }
  // Changes whenever a node's command refresh may have changed (any thread).
  std::uint64_t refresh_generation() const {
    return refresh_generation_.load(std::memory_order_acquire);
  }
  // How many times the node's command lapsed because its commander stopped
  // writing it (command_refresh_ms) (any thread).
  std::uint32_t silences(devicenet::MacId mac) const {
    return silences_[mac.value()].load(std::memory_order_acquire);
  }
  // `watch` is called on the port's thread after a pass that counted a
  // silence, and after the scan list changed (a node's profile or refresh
  // may have), so it must return at once; empty: none. Set and cleared from
  // any thread.
  void watch_command_state(std::function<void()> watch);

  // For a service manager, from any thread. The port has finished its
  // start-up checks once its master left the duplicate MAC ID check, either
  // scanning or refusing to send (another node has its MAC), or once it
  // found its interface down or absent: then it reports that, and its master
  // starts (the MAC check first) when the interface is up.
  bool started_up() const { return started_up_.load(std::memory_order_relaxed); }
  // Advances on every iteration of the loop, which wakes at least once per
  // status period: a value that stops advancing is a stalled loop.
  std::uint64_t heartbeat() const { return heartbeat_.load(std::memory_order_relaxed); }
  // Nodes online as of the last PortStatus.
  std::uint16_t nodes_online() const { return nodes_online_.load(std::memory_order_relaxed); }
  std::size_t nodes_configured() const {
    return static_cast<std::size_t>(std::popcount(scan_list_.load(std::memory_order_relaxed)));
  }
  // What keeps the port off the bus as of the last PortStatus ("interface
  // can7 absent"); empty when nothing does.
  std::string problem() const;

 private:
  // Each for the node of the profile the MAC had when it was queued.
  struct Command {
    devicenet::MacId mac;
    std::string_view profile;
    rack::NodeCommand command;
    std::string issuer;
  };
  struct Release {
    devicenet::MacId mac;
    std::string_view profile;
  };
  struct Stop {};
  struct Reconfigure {
    std::shared_ptr<PortLoopConfig> config;
    std::shared_ptr<std::promise<PortChange>> done;
  };
  using Item =
      std::variant<Command, Release, Stop, ScanCall, Reconfigure, std::function<void(CanBackend&)>>;
  void apply(const Reconfigure& r, TimePoint now);
  void note_scan_list();

  void run();
  // Starts the master once the interface is up: its duplicate MAC ID check
  // must reach the bus to mean anything.
  void start_master_when_up(TimePoint now);
  void push(Item item);
  // Commands first, then at most kCallsPerPass explicit requests: a node's
  // command never waits behind explicit traffic, nor the bus behind a flood
  // of requests. False once a Stop was seen.
  bool drain_inbox(TimePoint now);
  bool calls_waiting_ = false;  // requests left for the next pass
  // What the bus's state says to the master: a bus that came back makes it
  // check its MAC again. A change of the bus's state is published at once.
  void follow_bus(const BusCounters& counters, bool master_was_started, bool stopping,
                  TimePoint now);
  // The earliest time any part of the port next needs a pass.
  TimePoint next_wake(TimePoint stop_deadline) const;
  void publish(TimePoint now, bool force);
  void publish_port(TimePoint now);
  std::vector<BusMetrics::NodePolls> node_polls() const;

  // ScannerObserver, after the rack model (port_): what the loop itself
  // does with the master's events (the port's status, a log line, the
  // gateway's replies).
  void on_port_state(devicenet::PortState s, const std::string& r, TimePoint at) override;
  void on_node_state(devicenet::MacId m, devicenet::NodeState f, devicenet::NodeState t,
                     const std::string& r, TimePoint at) override;
  void on_unconfigured_node(devicenet::MacId, TimePoint) override { status_.changed(); }
  void on_bus_scan(const devicenet::BusScan& scan, TimePoint at) override {
    scans_.on_bus_scan(scan, at);
  }
  void handle_scan_call(const ScanCall& call, TimePoint now);
  void on_explicit_result(std::uint32_t id, devicenet::MacId m, const devicenet::ExplicitResult& r,
                          TimePoint at) override;
  // FrameReceiver
  void on_frame(const can::CanFrame& frame, TimePoint rx_time) override;

  PortLoopConfig config_;
  std::unique_ptr<CanBackend> backend_;
  PortPublisher& publisher_;
  Logger log_;
  std::optional<rack::RackPort> port_;  // the master and the rack model
  devicenet::Scanner& scanner() { return port_->scanner(); }
  std::optional<rack::ExplicitGateway> gateway_;

  NodePublication publication_;
  PortStatusSchedule status_;
  BusMetrics metrics_;
  BusScans scans_;
  std::optional<PortReconfiguration> reconfiguration_;
  bool master_started_ = false;
  BusState bus_state_ = BusState::kUnknown;  // as last published
  BusState bus_seen_ = BusState::kUnknown;   // as last seen by the loop
  std::uint64_t bus_losses_seen_ = 0;        // BusCounters::losses, likewise

  // The longest the loop was busy at once since the last PortStatus: a pass
  // (woken to waiting again) or the handling of one received frame, on the
  // steady clock whatever clock the backend runs on.
  void note_busy(std::chrono::steady_clock::time_point since);
  Duration longest_pass_{};

  std::atomic<std::uint64_t> scan_list_{0};  // bit per MAC; set on the port's thread
  // Per MAC, 1 + the index of its profile in profile_names_; 0: none. A
  // profile's name is appended (on the port's thread, when a rack of it first
  // comes) before any MAC's release store names it, and never changes: a
  // reader on another thread that sees the index sees the name.
  std::array<std::atomic<std::uint8_t>, devicenet::MacId::kMax + 1> profile_of_{};
  static constexpr std::size_t kMaxProfiles = 16;
  std::array<std::string_view, kMaxProfiles> profile_names_{};
  std::size_t profile_count_ = 0;  // port's thread only
  std::uint8_t profile_index(std::string_view name);
  std::array<std::atomic<std::uint32_t>, devicenet::MacId::kMax + 1> refresh_ms_{};
  std::atomic<std::uint64_t> refresh_generation_{0};
  // Commands not written again within their node's command refresh: idle.
  void expire_silent_commanders(TimePoint now);
  RateLimitedLog silent_log_;  // a commander writing just slower than its refresh
  std::array<std::atomic<std::uint32_t>, devicenet::MacId::kMax + 1> silences_{};
  std::mutex command_watch_mutex_;
  std::function<void()> command_watch_;
  std::mutex inbox_mutex_;
  std::vector<Item> inbox_;
  std::deque<rack::ExplicitCall> calls_;
  std::atomic<std::uint64_t> calls_refused_{0};  // kMaxQueuedCalls reached
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> started_up_{false};
  std::atomic<std::uint64_t> heartbeat_{0};
  std::atomic<std::uint16_t> nodes_online_{0};
  mutable std::mutex problem_mutex_;
  std::string problem_;
};

}  // namespace dnbridge::port
