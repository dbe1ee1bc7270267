#pragma once
// What reaches the bridge from DDS: commands, explicit requests, bus scan
// requests and reload requests for this rack, each handed to its port's
// loop through the loop's inbox; nothing here touches master state. Every
// command topic (one per profile: PumpCommand commands the CDN127s,
// DeviceCommand the devices described by their EDS) takes one path: the
// profile's CommandTopic (profile_topics.hpp) makes its readers, and a
// sample becomes a CommandSample, whose outputs are a rack::NodeCommand for
// the node's port loop.
// Commands are taken by a listener, on the Cyclone thread that delivers
// them, and handed over at once (take, push, wake: nothing that waits);
// under a flood, at most once per hold-off, the rest by the input's own
// thread at its end. There is one reader per command topic and command
// refresh the rack's nodes have (their requested deadline:
// dds::command_reader_qos), each taking only its own nodes' commands, all
// with the rack's lease bound. A node whose commander went silent (its
// command not written again within the node's refresh) has its commands
// taken from then on by readers of its own, made afresh: see node_readers_.
// Requests are taken on the input's own thread, from a waitset.
// Requests for other racks are left to their bridges.
#include <array>
#include <atomic>
#include <functional>
#include <map>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <tuple>
#include <vector>

#include "adapters/daemon/dds_publisher.hpp"
#include "adapters/daemon/profile_topics.hpp"
#include "adapters/dds/listener.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/port/port_loop.hpp"
#include "bridge/common/log.hpp"

namespace dnbridge::daemon {

// Lines written on one thread, said on another: the command path logs on
// Cyclone's thread, where a sink that blocks (a full pipe, a slow journal)
// would hold up delivery. At most kCapacity wait; more are counted and said.
class HandoffLogSink : public LogSink {
 public:
  static constexpr std::size_t kCapacity = 32;
  // `ready` is called (on the writing thread) when a line is waiting.
  HandoffLogSink(LogSink& target, std::function<void()> ready)
      : target_(target), ready_(std::move(ready)) {}
  bool enabled(LogLevel level) const noexcept override { return target_.enabled(level); }
  void write(LogLevel level, std::string_view component, std::string_view message) override {
    write_structured(level, component, message, {});
  }
  void write_structured(LogLevel level, std::string_view component, std::string_view message,
                        std::span<const LogField> fields) override;
  // Writes what waits to the target (the draining thread), in the order it
  // was written; returns how many lines were dropped since the last drain,
  // for the drainer to say with its own logger.
  std::size_t drain();

 private:
  struct Line {
    LogLevel level;
    std::string component, message;
    std::vector<std::pair<std::string, std::string>> fields;
  };
  LogSink& target_;
  std::function<void()> ready_;
  std::mutex mutex_;
  std::vector<Line> lines_;
  std::size_t dropped_ = 0;
};

// A thread's own lines after the lines handed off before them: before each
// line it writes, `before` writes out what a HandoffLogSink holds, so the log
// keeps the order in which the lines were written. For one writing thread at
// a time (two that drain at once may interleave what they write). `before`
// may log through this sink: it is not called again from within, nor, on
// that thread, is any DrainFirstLogSink's.
class DrainFirstLogSink : public LogSink {
 public:
  DrainFirstLogSink(LogSink& target, std::function<void()> before)
      : target_(target), before_(std::move(before)) {}
  bool enabled(LogLevel level) const noexcept override { return target_.enabled(level); }
  void write(LogLevel level, std::string_view component, std::string_view message) override {
    write_structured(level, component, message, {});
  }
  void write_structured(LogLevel level, std::string_view component, std::string_view message,
                        std::span<const LogField> fields) override;
  LogSink& target() const noexcept { return target_; }

 private:
  LogSink& target_;
  std::function<void()> before_;
  static thread_local bool in_before_;
};

class DdsInput {
 public:
  // `reload`: called (on the input's thread) with each reload request for
  // this rack; it must return at once (Daemon::request_reload queues it).
  // `max_commander_lease`: the rack's max_commander_lease_ms.
  DdsInput(const dds::Participant& participant, DdsPublisher& publisher, std::string rack,
           std::map<std::string, port::PortLoop*, std::less<>> ports, Logger log,
           std::function<void(ReloadCall)> reload = {},
           Duration max_commander_lease = dds::kDefaultMaxCommanderLease,
           std::span<const ProfileTopics> profiles = bridge_profiles());
  ~DdsInput();
  DdsInput(const DdsInput&) = delete;
  DdsInput& operator=(const DdsInput&) = delete;

  void start();
  // Returns when the thread has ended and no command is being handed over.
  void stop();

  // Makes the command readers of these command refreshes (ms; 0: none)
  // that do not exist yet, at once: called before a reload gives a node a
  // new refresh (any thread).
  void prepare_command_refreshes(const std::vector<std::uint32_t>& refreshes);

  // Samples with data for this rack taken so far (any thread).
  std::uint64_t commands_taken() const noexcept { return commands_taken_.load(); }
  // Times commands came within the hold-off after a take (a flood) and were
  // left in the reader for the input thread to take at its end.
  std::uint64_t command_holdoffs() const noexcept { return command_holdoffs_.load(); }
  std::uint64_t requests_taken() const noexcept { return requests_taken_.load(); }

 private:
  void run();
  // A command arrived (Cyclone's thread): hand it over now, unless within
  // the hold-off.
  void on_commands_available();
  // Takes and hands over the commands waiting, unless another thread is at
  // it (then that one does) or the hold-off is on (then the input thread
  // does at its end). Any thread.
  void deliver_commands();
  // Logs the command path's waiting lines (HandoffLogSink), and how many
  // were dropped, with this input's logger.
  void drain_command_log();
  // The command readers of the nodes with one command refresh (0: none),
  // or of one node (node_readers_): one per command topic (of the node's
  // profile, for a node's own).
  struct CommandClass;
  // Every command reader's commands; one class's.
  void take_commands();
  void take_commands(const CommandClass& from);
  bool take_requests();  // true when requests may remain
  void take_scan_requests();
  void on_scan_request(const dds::Sample<dnbridge_BusScanRequest>& sample);
  void take_reload_requests();
  // A command sample taken by a reader of `from`, of any command topic.
  void on_command(const CommandSample& c, const CommandClass& from);
  // The port loop a command sample is for, when the MAC is a node of that
  // loop of the profile the topic commands and of the reader's command
  // refresh; else null, and a refusal (a node not in the rack, or of
  // another profile) is logged (rate-limited).
  port::PortLoop* loop_for(const CommandSample& c, const CommandClass& from);
  // A class of command readers for every command refresh the ports' nodes
  // have now (none is deleted before stop). Under command_take_mutex_.
  void ensure_command_classes();
  // The class of `refresh_ms`, made if missing; a failure is logged (the
  // nodes of that refresh then take no command: their commands lapse).
  // Under command_take_mutex_.
  void ensure_command_class(std::uint32_t refresh_ms);
  // node_readers_: a node's own readers, for a node whose commander went
  // silent. Exclusive
  // ownership keeps a silent writer that is still live the owner of its
  // instance in every reader that has it (Cyclone DDS renews an instance's
  // deadline on the samples ownership refuses, so the owner never misses
  // it while a weaker writer writes): a weaker live commander would never
  // take over. A reader made afresh, volatile, has no owner for the node:
  // the next sample of any live commander of the node owns it there, and a
  // stronger one's takes it back. At most one reader per node, made again at
  // each silence of its commander (the port loop counts them:
  // PortLoop::silences). A reload that changes the node's refresh or profile
  // makes it stale: from then on its class takes the node's commands
  // (loop_for), and the input drops it when the port loop wakes it. Under
  // command_take_mutex_.
  using NodeKey = CommandedNode;
  // A node by port and MAC, found without a copy of its port's name.
  struct NodeRef {
    std::string_view port;
    std::uint8_t mac;
  };
  struct NodeOrder {
    using is_transparent = void;
    static NodeRef ref(const NodeKey& k) { return {k.port, k.mac}; }
    static NodeRef ref(NodeRef r) { return r; }
    template <class A, class B>
    bool operator()(const A& a, const B& b) const {
      const NodeRef x = ref(a);
      const NodeRef y = ref(b);
      return std::tie(x.port, x.mac) < std::tie(y.port, y.mac);
    }
  };
  void make_readers_of_silenced_nodes();
  void make_node_readers(const std::string& port, devicenet::MacId mac, std::string_view profile,
                         std::uint32_t refresh_ms);
  // Drops the node readers of nodes whose profile or refresh changed since.
  void drop_stale_node_readers();
  bool classes_closed_ = false;  // stop(): no class is made after it (under the mutex)
  std::uint64_t refresh_generations() const;
  void on_request(const dnbridge_ExplicitRequest& r, std::span<const unsigned char> serialized);
  void note_clock_skew(const CommandSample& c);
  port::PortLoop* port_of(std::string_view name);

  std::string rack_;
  DdsPublisher& publisher_;
  std::map<std::string, port::PortLoop*, std::less<>> ports_;
  Logger log_;
  // The rack's partition: DDS delivers this bridge its own rack's commands
  // and requests only (dds::rack_partition).
  std::vector<std::string> partition_;
  // Commands: taken by one thread at a time (the mutex); a thread that finds
  // it taken leaves `commands_pending_` set for the one that holds it.
  std::mutex command_take_mutex_;
  std::atomic<bool> commands_pending_{false};
  std::atomic<bool> accepting_{false};       // between start() and stop()
  std::atomic<bool> held_signalled_{false};  // the input thread takes them at the hold-off's end
  std::atomic<TimePoint::rep> next_command_take_{0};  // steady clock ticks
  dds::GuardCondition commands_held_;
  const dds::Participant& participant_;
  Duration max_commander_lease_;
  dds::DataListener command_listener_;  // before the readers: it outlives them
  // The command topics, before the readers: they outlive them. A topic DDS
  // Security does not grant is absent (unless_denied).
  std::vector<std::unique_ptr<CommandTopic>> command_topics_;
  struct CommandClass {
    std::uint32_t refresh_ms;  // 0: the nodes without a command refresh
    // A node's own readers: the node (their topic's filter's argument);
    // null for a class of nodes.
    std::unique_ptr<NodeKey> node;
    std::string_view profile;  // a node's own: the node's profile
    std::vector<std::unique_ptr<CommandReader>> readers;
  };
  // Guarded by command_take_mutex_; classes are added, never removed, while
  // the input runs (a listener call may be on any of them).
  std::vector<std::unique_ptr<CommandClass>> command_classes_;
  // Guarded by command_take_mutex_: a reader deleted under it may have a
  // listener call in progress, which finds the mutex taken and returns.
  std::map<NodeKey, std::unique_ptr<CommandClass>, NodeOrder> node_readers_;
  // The port loops' silence counts as last looked at (the input thread's).
  std::map<std::string, std::array<std::uint32_t, devicenet::MacId::kMax + 1>, std::less<>>
      silences_seen_;
  std::uint64_t classes_for_generation_ = ~0ull;  // the ports' refresh generations then
  dds::Reader<dnbridge_ExplicitRequest> requests_;
  // Absent when DDS Security does not grant the service (unless_denied).
  std::optional<dds::Reader<dnbridge_BusScanRequest>> scan_requests_;
  std::optional<dds::Reader<dnbridge_ReloadRequest>> reload_requests_;
  std::function<void(ReloadCall)> reload_;
  dds::TakeBuffer<dnbridge_ExplicitRequest> request_buffer_;
  std::vector<std::vector<unsigned char>> request_cdr_;
  dds::GuardCondition stop_;
  dds::WaitSet waitset_;
  std::thread thread_;
  RateLimitedLog warn_limit_;          // the input thread's
  RateLimitedLog command_warn_limit_;  // these two: whichever thread takes commands,
  RateLimitedLog skew_limit_;          // through command_log_
  dds::GuardCondition log_waiting_;
  dds::GuardCondition silenced_;  // a port loop counted a silence
  HandoffLogSink command_sink_;
  Logger command_log_;  // log_ through command_sink_
  // log_'s sink once constructed: the input's own lines come after the
  // command path's lines handed off before them.
  DrainFirstLogSink own_sink_;
  std::atomic<std::uint64_t> commands_taken_{0};
  std::atomic<std::uint64_t> command_holdoffs_{0};
  std::atomic<std::uint64_t> requests_taken_{0};
  std::uint64_t commands_stamped_ahead_ = 0;
  std::uint64_t requests_refused_for_names_ = 0;
  std::uint64_t requests_dropped_for_size_ = 0;
};

}  // namespace dnbridge::daemon
