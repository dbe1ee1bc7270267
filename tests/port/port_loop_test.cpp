// A port's event loop on its own thread, on the simulated bus in real time:
// it brings nodes online, applies commands from another thread, answers
// explicit requests, publishes, and shuts down in order. Waits are bounded
// waits for events, never sleeps.
#include "adapters/port/port_loop.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>
#include <pthread.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <future>
#include <map>
#include <mutex>
#include <regex>
#include <string>
#include <vector>

#include "adapters/sim/world/sim_backend.hpp"
#include "adapters/sim/world/threaded_sim_backend.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::port {
namespace {

using devicenet::MacId;
MacId mac(unsigned v) { return MacId::from(v).value(); }

class RecordingPublisher final : public PortPublisher {
 public:
  // The pumps' states (the only profile these tests configure).
  void node_state(const std::string&, const rack::NodeView& node, TimePoint t) override {
    ASSERT_EQ(node.profile, rack::PumpProfile::kName);
    std::lock_guard lock(mutex_);
    pumps[node.mac.value()] = static_cast<const rack::PumpView&>(node);
    pump_times[node.mac.value()] = t;
    ++pump_samples;
    changed_.notify_all();
  }
  void node_status(const std::string&, const rack::NodeView& node, const NodeStatusView& status,
                   TimePoint) override {
    std::lock_guard lock(mutex_);
    node_states[node.mac.value()] = status.state;
    ++status_samples;
    changed_.notify_all();
  }
  void port_status(const PortStatusView& s, TimePoint) override {
    std::lock_guard lock(mutex_);
    if (port_reasons.empty() || port_reasons.back() != s.reason) port_reasons.push_back(s.reason);
    port = s;
    ++port_samples;
    changed_.notify_all();
  }
  void bus_scan_reply(const std::string&, const BusScanAnswer& a) override {
    std::lock_guard lock(mutex_);
    scans.push_back(a);
    changed_.notify_all();
  }
  void explicit_reply(const std::string&, const rack::ExplicitAnswer& a) override {
    std::lock_guard lock(mutex_);
    replies.push_back(a);
    changed_.notify_all();
  }
  void port_stopped(const std::string&) override {
    std::lock_guard lock(mutex_);
    stopped = true;
    changed_.notify_all();
  }
  void node_removed(const std::string&, MacId m) override {
    std::lock_guard lock(mutex_);
    removed.push_back(m.value());
    pumps.erase(m.value());
    changed_.notify_all();
  }

  // Waits (at most `timeout`) until `done()` holds; checked under the lock.
  template <class F>
  bool wait_for(F done, std::chrono::seconds timeout = std::chrono::seconds(10)) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, done);
  }

  std::mutex& mutex() { return mutex_; }

  PortStatusView last_port() {
    std::lock_guard lock(mutex_);
    return port.value_or(PortStatusView{});
  }

  std::map<unsigned, rack::PumpView> pumps;
  std::map<unsigned, TimePoint> pump_times;
  std::map<unsigned, devicenet::NodeState> node_states;
  std::optional<PortStatusView> port;
  std::vector<std::string> port_reasons;  // each new one
  std::vector<rack::ExplicitAnswer> replies;
  std::vector<BusScanAnswer> scans;
  std::vector<unsigned> removed;  // node_removed, in order
  std::size_t pump_samples = 0, status_samples = 0, port_samples = 0;
  bool stopped = false;

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
};

// The simulated bus behind an interface that is absent until plug_in(), as
// the SocketCAN backend reports one: bus down, its problem said, and no frame
// through either way.
class UnpluggedBackend final : public CanBackend, private can::FrameSink {
 public:
  explicit UnpluggedBackend(std::unique_ptr<sim::SimBackend> bus) : bus_(std::move(bus)) {}
  // Any thread.
  void plug_in() {
    plugged_ = true;
    bus_->wake();
  }
  void unplug() {
    plugged_ = false;
    bus_->wake();
  }
  // The bus lost and back between two looks of the port's loop at its
  // state: only the count of losses tells.
  void lose_unseen() {
    losses_.fetch_add(1);
    bus_->wake();
  }
  std::uint64_t dropped() const { return dropped_; }

  can::FrameSink& sink() override { return *this; }
  TimePoint now() const override { return bus_->now(); }
  void wait(TimePoint deadline, FrameReceiver& receiver) override {
    struct Gate final : FrameReceiver {
      Gate(const UnpluggedBackend& b, FrameReceiver& r) : backend(b), receiver(r) {}
      void on_frame(const can::CanFrame& f, TimePoint t) override {
        if (backend.plugged_) receiver.on_frame(f, t);
      }
      const UnpluggedBackend& backend;
      FrameReceiver& receiver;
    } gate(*this, receiver);
    bus_->wait(deadline, gate);
  }
  void wake() override { bus_->wake(); }
  BusCounters counters() const override {
    BusCounters c = bus_->counters();
    if (!plugged_) c.state = BusState::kDown;
    c.losses = losses_.load();
    return c;
  }
  std::string interface_name() const override { return "can7"; }
  std::uint32_t bitrate() const override { return bus_->bitrate(); }
  std::string problem() const override { return plugged_ ? "" : "interface can7 absent"; }

 private:
  void send(const can::CanFrame& frame, TimePoint now) override {
    if (plugged_) {
      bus_->sink().send(frame, now);
    } else {
      ++dropped_;
    }
  }

  std::unique_ptr<sim::SimBackend> bus_;
  std::atomic<bool> plugged_{false};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> losses_{0};
};

PortLoopConfig config_for(const std::vector<unsigned>& macs) {
  PortLoopConfig c;
  c.port = "A";
  c.scanner.master_mac = mac(0);
  c.status_period = milliseconds(200);
  for (unsigned m : macs) {
    rack::PumpConfig p;
    p.node.mac = mac(m);
    p.node.name = "pump-" + std::to_string(m);
    p.node.poll_period = milliseconds(20);
    p.node.expected_packet_rate = milliseconds(100);
    p.io = profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn127);
    c.nodes.of<rack::PumpConfig>().push_back(p);
    c.publish[mac(m)] = {milliseconds(500), 0.05};
  }
  return c;
}

TEST(PortLoop, RunsARackOnItsOwnThread) {
  RecordingPublisher publisher;
  const std::vector<unsigned> macs{1, 2, 3};
  std::vector<MacId> devices;
  for (unsigned m : macs) devices.push_back(mac(m));
  PortLoop loop(config_for(macs), std::make_unique<sim::SimBackend>(can::kBitrate500k, devices),
                publisher, null_log_sink());
  loop.start();

  ASSERT_TRUE(publisher.wait_for([&] {
    return std::all_of(macs.begin(), macs.end(), [&](unsigned m) {
      return publisher.pumps.count(m) && publisher.pumps[m].online && publisher.pumps[m].has_inputs;
    });
  }));

  profiles::cdn127::PumpOutputs out;
  out.pump_on = true;
  out.analog_out_raw = 2000;
  loop.command(mac(2), rack::NodeCommand(out), "supervisor-1");
  ASSERT_TRUE(publisher.wait_for([&] {
    const auto& v = publisher.pumps[2];
    return !v.outputs_idle && v.outputs_applied == out && v.commanded_by == "supervisor-1";
  }));

  rack::ExplicitCall call;
  call.requester = "test";
  call.txid = 42;
  call.command = 1;
  call.port = "A";
  call.mac = 3;
  call.service = 0x0E;
  call.class_id = 1;
  call.instance_id = 1;
  call.attribute = 7;
  loop.explicit_request(call);
  ASSERT_TRUE(publisher.wait_for([&] { return !publisher.replies.empty(); }));
  EXPECT_EQ(publisher.replies[0].status, rack::TransactionStatus::kSuccess);
  EXPECT_EQ(publisher.replies[0].data.size(), 7u);

  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.port && publisher.port->nodes_online == 3; }));
  {
    // Polled every 20 ms: the measured cycle says so.
    ASSERT_TRUE(publisher.wait_for([&] { return publisher.port->scan_cycle_ms > 0; }));
    // Real time on a loaded machine (a sanitizer build beside it): polls may
    // be late, never early, so the bound above is the looser one.
    EXPECT_GE(publisher.port->scan_cycle_ms, 18.0);
    EXPECT_LE(publisher.port->scan_cycle_ms, 35.0);
    EXPECT_GT(publisher.port->frames_per_second, 100.0);
    EXPECT_GT(publisher.port->bus_load_percent, 0.0);
  }

  // The simulated device really applies what was commanded.
  std::promise<bool> pump_on;
  loop.post([&](CanBackend& b) {
    pump_on.set_value(static_cast<sim::SimBackend&>(b).device(mac(2)).device().outputs().pump_on);
  });
  EXPECT_TRUE(pump_on.get_future().get());

  loop.stop();
  loop.join();
  EXPECT_TRUE(publisher.stopped);
  for (unsigned m : macs) {
    EXPECT_EQ(publisher.node_states[m], devicenet::NodeState::kStopped) << m;
    EXPECT_FALSE(publisher.pumps[m].online) << m;
  }
}

// A node's state change in the log carries the fields the journal keeps:
// PORT, MAC and NODE (the node's MAC ID), NODE_STATE.
TEST(PortLoop, ANodesStateChangeIsLoggedWithItsFields) {
  class Capture final : public LogSink {
   public:
    bool enabled(LogLevel level) const noexcept override { return level >= LogLevel::kInfo; }
    void write(LogLevel, std::string_view, std::string_view) override {}
    void write_structured(LogLevel, std::string_view, std::string_view message,
                          std::span<const LogField> fields) override {
      std::lock_guard lock(mutex);
      std::string line(message);
      for (const auto& f : fields) line += fmt::format(" {}={}", f.name, f.value);
      lines.push_back(std::move(line));
    }
    std::mutex mutex;
    std::vector<std::string> lines;
  } log;
  RecordingPublisher publisher;
  PortLoop loop(config_for({2}),
                std::make_unique<sim::SimBackend>(can::kBitrate500k, std::vector<MacId>{mac(2)}),
                publisher, log);
  loop.start();
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.pumps.count(2) && publisher.pumps[2].online; }));
  loop.stop();
  loop.join();
  std::lock_guard lock(log.mutex);
  const auto has = [&](const std::string& what) {
    return std::any_of(log.lines.begin(), log.lines.end(),
                       [&](const std::string& l) { return l.find(what) != std::string::npos; });
  };
  EXPECT_TRUE(has("-> online: ") && has(" PORT=A MAC=2 NODE=2 NODE_STATE=online"))
      << fmt::format("{}", fmt::join(log.lines, "\n"));
  EXPECT_TRUE(has(" PORT=A MAC=2 NODE=2 NODE_STATE=stopped"))
      << fmt::format("{}", fmt::join(log.lines, "\n"));
}

// SIGUSR1's candump log on the simulated bus: both directions, as candump -l
// writes them, until it is stopped.
TEST(PortLoop, TheSimulatedBusWritesACandumpLog) {
  RecordingPublisher publisher;
  PortLoop loop(config_for({1}),
                std::make_unique<sim::SimBackend>(can::kBitrate500k, std::vector<MacId>{mac(1)}),
                publisher, null_log_sink());
  loop.start();
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.pumps.count(1) && publisher.pumps[1].online; }));

  const std::string path = ::testing::TempDir() + "port-loop-candump.log";
  std::remove(path.c_str());
  std::promise<bool> started;
  loop.post(
      [&](CanBackend& b) { started.set_value(b.candump().start(path, b.interface_name()).ok()); });
  ASSERT_TRUE(started.get_future().get());

  // The master's poll to MAC 1 (group 2 message 5: 40D) and the device's
  // response (group 1 message 15: 3C1), each at least twice.
  const auto lines = [&] {
    std::ifstream in(path);
    std::vector<std::string> all;
    for (std::string line; std::getline(in, line);) all.push_back(line);
    return all;
  };
  const auto count = [&](const std::string& id) {
    const auto all = lines();
    return std::count_if(all.begin(), all.end(), [&](const std::string& l) {
      return l.find(" simulated " + id + "#") != std::string::npos;
    });
  };
  ASSERT_TRUE(publisher.wait_for([&] { return count("40D") >= 2 && count("3C1") >= 2; }))
      << "log: " << lines().size() << " lines";

  std::promise<void> stopped;
  loop.post([&](CanBackend& b) {
    b.candump().stop();
    stopped.set_value();
  });
  stopped.get_future().get();
  for (const auto& line : lines()) {
    EXPECT_TRUE(std::regex_match(
        line, std::regex(R"(\(\d+\.\d{6}\) simulated [0-9A-F]{3}#([0-9A-F]{2})*)")))
        << line;
  }
  loop.stop();
  loop.join();
  std::remove(path.c_str());
}

TEST(PortLoop, TheExplicitGatewayFollowsTheConfiguredPolicy) {
  RecordingPublisher publisher;
  PortLoopConfig config = config_for({5});
  config.explicit_policy.allow_output_writes = true;
  PortLoop loop(std::move(config),
                std::make_unique<sim::SimBackend>(can::kBitrate500k, std::vector<MacId>{mac(5)}),
                publisher, null_log_sink());
  loop.start();
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.pumps.count(5) && publisher.pumps[5].online; }));

  rack::ExplicitCall call;
  call.requester = "test";
  call.command = 1;
  call.port = "A";
  call.mac = 5;
  call.instance_id = 1;
  // Allowed by this rack: a Set of DOP 1's Value reaches the device.
  call.txid = 1;
  call.service = 0x10;
  call.class_id = 0x09;
  call.attribute = 3;
  call.data = {0x01};
  loop.explicit_request(call);
  // Not allowed: a Reset of the Identity object.
  call.txid = 2;
  call.service = 0x05;
  call.class_id = 0x01;
  call.attribute.reset();
  call.data.clear();
  loop.explicit_request(call);
  ASSERT_TRUE(publisher.wait_for([&] { return publisher.replies.size() == 2; }));
  std::map<std::uint32_t, rack::ExplicitAnswer> by_txid;
  for (const auto& r : publisher.replies) by_txid[r.txid] = r;
  EXPECT_EQ(by_txid[1].status, rack::TransactionStatus::kSuccess) << by_txid[1].message;
  EXPECT_EQ(by_txid[2].status, rack::TransactionStatus::kInvalidCommand);
  EXPECT_NE(by_txid[2].message.find("allow_identity_reset = true"), std::string::npos)
      << by_txid[2].message;
  loop.stop();
  loop.join();
}

TEST(PortLoop, BadCommandsAreRefusedAndReported) {
  RecordingPublisher publisher;
  PortLoop loop(config_for({4}),
                std::make_unique<sim::SimBackend>(can::kBitrate500k, std::vector<MacId>{mac(4)}),
                publisher, null_log_sink());
  loop.start();
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.pumps.count(4) && publisher.pumps[4].online; }));
  profiles::cdn127::PumpOutputs out;
  out.analog_out_raw = 9999;
  loop.command(mac(4), rack::NodeCommand(out), "careless");
  ASSERT_TRUE(publisher.wait_for([&] { return publisher.pumps[4].commands_refused == 1; }));
  EXPECT_NE(publisher.pumps[4].last_command_refused.find("9999"), std::string::npos);
  // Outputs in the form of another profile (an EDS device's bytes).
  loop.command(mac(4), rack::NodeCommand(std::vector<std::uint8_t>{1}), "careless");
  ASSERT_TRUE(publisher.wait_for([&] { return publisher.pumps[4].commands_refused == 2; }));
  EXPECT_EQ(publisher.pumps[4].last_command_refused,
            "from careless: not a command for a node of profile \"cdn127\"");
  // Only the scan list's MACs are commanded; another one is refused where it
  // comes in (DdsInput asks profile_of), and the loop refuses it too.
  EXPECT_TRUE(loop.has_node(mac(4)));
  EXPECT_EQ(loop.profile_of(mac(4)), "cdn127");
  EXPECT_FALSE(loop.has_node(mac(5)));
  EXPECT_EQ(loop.profile_of(mac(5)), "");
  EXPECT_FALSE(loop.has_node(mac(63)));
  loop.command(mac(5), rack::NodeCommand(profiles::cdn127::PumpOutputs{}), "careless");
  std::promise<void> handled;
  loop.post([&](CanBackend&) { handled.set_value(); });
  handled.get_future().wait();
  EXPECT_EQ(publisher.pumps.count(5), 0u);
  loop.stop();
  loop.join();
}

// `count` requests for the status of transactions never started: each is
// answered at once, by the port loop, with "txid unknown".
void queue_status_requests(PortLoop& loop, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    rack::ExplicitCall call;
    call.requester = "flood-" + std::to_string(i);
    call.txid = 1;
    call.command = 2;
    call.port = "A";
    call.mac = 4;
    loop.explicit_request(call);
  }
}

// A flood of requests is handled kCallsPerPass at a time: between two
// batches the loop goes back to its timers and the bus, and nothing queued
// is lost on the way.
TEST(PortLoop, AFloodOfRequestsIsHandledAFewAtATimeBetweenPasses) {
  constexpr std::size_t kCalls = 3 * PortLoop::kCallsPerPass + 5;
  RecordingPublisher publisher;
  // At the start of every pass (posted jobs run first), the replies so far.
  std::vector<std::size_t> at_pass_start;
  std::function<void(CanBackend&)> record;
  PortLoop loop(config_for({4}),
                std::make_unique<sim::SimBackend>(can::kBitrate500k, std::vector<MacId>{mac(4)}),
                publisher, null_log_sink());
  loop.start();
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.pumps.count(4) && publisher.pumps[4].online; }));

  // The loop held in a pass while the flood is queued.
  std::promise<void> held, release;
  loop.post([&](CanBackend&) {
    held.set_value();
    release.get_future().wait();
  });
  held.get_future().wait();
  queue_status_requests(loop, kCalls);
  record = [&](CanBackend&) {
    std::size_t replies = 0;
    {
      std::lock_guard lock(publisher.mutex());
      replies = publisher.replies.size();
    }
    at_pass_start.push_back(replies);
    if (replies < kCalls) loop.post(record);
  };
  loop.post(record);
  release.set_value();
  ASSERT_TRUE(publisher.wait_for([&] { return publisher.replies.size() == kCalls; }));
  std::promise<void> recorded;
  loop.post([&](CanBackend&) { recorded.set_value(); });
  recorded.get_future().wait();

  ASSERT_GE(at_pass_start.size(), 4u);
  EXPECT_EQ(at_pass_start.front(), 0u);
  for (std::size_t i = 1; i < at_pass_start.size(); ++i) {
    EXPECT_LE(at_pass_start[i] - at_pass_start[i - 1], PortLoop::kCallsPerPass) << "pass " << i;
  }
  for (const auto& r : publisher.replies) {
    EXPECT_EQ(r.status, rack::TransactionStatus::kTxidUnknown) << r.message;
  }
  loop.stop();
  loop.join();
}

// Requests queued when the port stops are answered before its loop ends,
// even when the master has nothing to release (no node ever answered).
TEST(PortLoop, RequestsQueuedAtStopAreAllAnswered) {
  constexpr std::size_t kCalls = 3 * PortLoop::kCallsPerPass + 5;
  RecordingPublisher publisher;
  PortLoop loop(config_for({4}),
                std::make_unique<sim::SimBackend>(can::kBitrate500k, std::vector<MacId>{}),
                publisher, null_log_sink());
  loop.start();
  std::promise<void> held, release;
  loop.post([&](CanBackend&) {
    held.set_value();
    release.get_future().wait();
  });
  held.get_future().wait();
  queue_status_requests(loop, kCalls);
  loop.stop();
  release.set_value();
  loop.join();
  EXPECT_EQ(publisher.replies.size(), kCalls);
}

// The world on a thread of its own (what the benchmark measures the bridge
// with): the same rack comes online, commands reach the devices, and the
// world's CPU time is accounted apart.
TEST(PortLoop, RunsOnTheThreadedSimulatedBus) {
  RecordingPublisher publisher;
  const std::vector<unsigned> macs{1, 2};
  std::vector<MacId> devices;
  for (unsigned m : macs) devices.push_back(mac(m));
  auto backend = std::make_unique<sim::ThreadedSimBackend>(can::kBitrate500k, devices);
  sim::ThreadedSimBackend* world = backend.get();
  PortLoop loop(config_for(macs), std::move(backend), publisher, null_log_sink());
  loop.start();

  TimePoint received{};
  ASSERT_TRUE(publisher.wait_for([&] {
    received = publisher.pump_times[1];  // under the publisher's lock
    return std::all_of(macs.begin(), macs.end(), [&](unsigned m) {
      return publisher.pumps.count(m) && publisher.pumps[m].online && publisher.pumps[m].has_inputs;
    });
  }));
  // Receive times are on the backend's clock, never ahead of it.
  EXPECT_LE(received, world->now());

  profiles::cdn127::PumpOutputs out;
  out.pump_on = true;
  out.analog_out_raw = 1234;
  loop.command(mac(2), rack::NodeCommand(out), "supervisor-1");
  ASSERT_TRUE(publisher.wait_for([&] {
    const auto& v = publisher.pumps[2];
    return !v.outputs_idle && v.outputs_applied == out;
  }));
  std::promise<profiles::cdn127::PumpOutputs> applied;
  world->post([&] { applied.set_value(world->device(mac(2)).device().outputs()); });
  EXPECT_EQ(applied.get_future().get(), out);
  EXPECT_GT(world->counters().frames, 0u);
  EXPECT_GT(world->sim_thread_cpu_time(), Duration::zero());

  // The threads are named for top -H and debuggers.
  auto thread_name = [] {
    char name[16] = {};
    (void)pthread_getname_np(pthread_self(), name, sizeof name);
    return std::string(name);
  };
  std::promise<std::string> port_thread;
  loop.post([&](CanBackend&) { port_thread.set_value(thread_name()); });
  EXPECT_EQ(port_thread.get_future().get(), "port A");
  std::promise<std::string> world_thread;
  world->post([&] { world_thread.set_value(thread_name()); });
  EXPECT_EQ(world_thread.get_future().get(), "sim bus");

  loop.stop();
  loop.join();
  EXPECT_TRUE(publisher.stopped);
  for (unsigned m : macs) EXPECT_EQ(publisher.node_states[m], devicenet::NodeState::kStopped) << m;
}

// An interface absent at start ends the port's start-up checks at once (a
// service manager need not wait for it) with the port reported down; the
// master starts, duplicate MAC ID check first, only when the interface is
// there: a check nobody could hear proves nothing.
TEST(PortLoop, AnInterfaceAbsentAtStartEndsTheStartUpChecksAndTheMasterWaitsForIt) {
  RecordingPublisher publisher;
  auto backend = std::make_unique<UnpluggedBackend>(
      std::make_unique<sim::SimBackend>(can::kBitrate500k, std::vector<MacId>{mac(1)}));
  UnpluggedBackend* interface = backend.get();
  PortLoop loop(config_for({1}), std::move(backend), publisher, null_log_sink());
  EXPECT_FALSE(loop.started_up());
  loop.start();

  // Three status periods with the interface absent.
  ASSERT_TRUE(publisher.wait_for([&] { return publisher.port_samples >= 3; }));
  EXPECT_TRUE(loop.started_up());
  EXPECT_EQ(loop.problem(), "interface can7 absent");
  {
    const PortStatusView port = publisher.last_port();
    EXPECT_EQ(port.bus.state, BusState::kDown);
    EXPECT_EQ(port.state, devicenet::PortState::kStopped);
    EXPECT_EQ(port.reason,
              "interface can7 absent (waiting for the interface to start the MAC check)");
  }
  EXPECT_EQ(interface->dropped(), 0u) << "the master sent while the interface was absent";

  interface->plug_in();
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.pumps.count(1) && publisher.pumps[1].online; }));
  EXPECT_EQ(loop.problem(), "");
  EXPECT_EQ(interface->dropped(), 0u);
  loop.stop();
  loop.join();
  EXPECT_TRUE(publisher.stopped);
}

// The interface goes away while the rack runs and comes back: the master
// checks its own MAC again before it scans, and the node comes back online.
TEST(PortLoop, AnInterfaceBackUpMakesTheMasterCheckItsMacAgain) {
  RecordingPublisher publisher;
  auto backend = std::make_unique<UnpluggedBackend>(
      std::make_unique<sim::SimBackend>(can::kBitrate500k, std::vector<MacId>{mac(1)}));
  UnpluggedBackend* interface = backend.get();
  interface->plug_in();
  PortLoop loop(config_for({1}), std::move(backend), publisher, null_log_sink());
  loop.start();
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.pumps.count(1) && publisher.pumps[1].online; }));

  interface->unplug();
  ASSERT_TRUE(publisher.wait_for([&] {
    return publisher.port && publisher.port->bus.state == BusState::kDown &&
           !publisher.pumps[1].online;
  }));
  interface->plug_in();
  ASSERT_TRUE(publisher.wait_for([&] {
    return std::find(publisher.port_reasons.begin(), publisher.port_reasons.end(),
                     "the interface is up again: checking again that no other node has MAC 0") !=
           publisher.port_reasons.end();
  }));
  ASSERT_TRUE(publisher.wait_for([&] { return publisher.pumps[1].online; }));
  loop.stop();
  loop.join();
}

// A bus-off and its recovery both within one wait of the port's loop (the
// backend counts it): the master checks its MAC again as for a loss it saw,
// and the node is made afresh.
TEST(PortLoop, ABusLostAndBackWhileTheLoopWaitedIsStillALoss) {
  RecordingPublisher publisher;
  auto backend = std::make_unique<UnpluggedBackend>(
      std::make_unique<sim::SimBackend>(can::kBitrate500k, std::vector<MacId>{mac(1)}));
  UnpluggedBackend* interface = backend.get();
  interface->plug_in();
  PortLoop loop(config_for({1}), std::move(backend), publisher, null_log_sink());
  loop.start();
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.pumps.count(1) && publisher.pumps[1].online; }));

  interface->lose_unseen();
  ASSERT_TRUE(publisher.wait_for([&] {
    return std::find(publisher.port_reasons.begin(), publisher.port_reasons.end(),
                     "the bus was lost and is back: checking again that no other node has MAC "
                     "0") != publisher.port_reasons.end();
  }));
  ASSERT_TRUE(publisher.wait_for([&] { return !publisher.pumps[1].online; }));
  ASSERT_TRUE(publisher.wait_for([&] { return publisher.pumps[1].online; }));
  loop.stop();
  loop.join();
}

// Asked to stop before its interface ever came: it stops at once.
TEST(PortLoop, APortWaitingForItsInterfaceStopsAtOnce) {
  RecordingPublisher publisher;
  PortLoop loop(config_for({1}),
                std::make_unique<UnpluggedBackend>(std::make_unique<sim::SimBackend>(
                    can::kBitrate500k, std::vector<MacId>{mac(1)})),
                publisher, null_log_sink());
  loop.start();
  ASSERT_TRUE(publisher.wait_for([&] { return publisher.port_samples >= 1; }));
  loop.stop();
  loop.join();
  EXPECT_TRUE(publisher.stopped);
}

// Bus scan requests: two that come together get the one scan, which finds
// the device the scan list does not have; a port whose interface is absent
// answers "port off-line" at once and asks nothing.
TEST(PortLoop, BusScanRequestsShareAScanAndAPortOffTheBusRefusesThem) {
  RecordingPublisher publisher;
  PortLoopConfig config = config_for({1});
  config.scanner.scan_response_timeout = milliseconds(100);  // a silent MAC: 100 ms
  PortLoop loop(
      config,
      std::make_unique<sim::SimBackend>(can::kBitrate500k, std::vector<MacId>{mac(1), mac(9)}),
      publisher, null_log_sink());
  loop.start();
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.pumps.count(1) && publisher.pumps[1].online; }));
  loop.scan_request({"first", 1});
  loop.scan_request({"second", 7});
  loop.scan_request({"first", 1});  // written again while it waits: the same transaction
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.scans.size() >= 2; }, std::chrono::seconds(60)));
  {
    std::lock_guard lock(publisher.mutex());
    ASSERT_EQ(publisher.scans.size(), 2u) << "the repeated request waited twice";
    const BusScanAnswer& a = publisher.scans[0];
    const BusScanAnswer& b = publisher.scans[1];
    EXPECT_EQ(a.requester, "first");
    EXPECT_EQ(b.requester, "second");
    EXPECT_EQ(b.txid, 7u);
    for (const BusScanAnswer* x : {&a, &b}) {
      EXPECT_EQ(x->status, rack::TransactionStatus::kSuccess) << x->message;
      EXPECT_EQ(x->age, Duration::zero()) << "not the scan run for it";
      EXPECT_EQ(x->duration, a.duration);
      ASSERT_EQ(x->findings.size(), 62u);  // all but the master (0) and node 1
      const auto& at9 = x->findings[7];
      EXPECT_EQ(at9.mac, mac(9));
      EXPECT_EQ(at9.outcome, devicenet::ScanOutcome::kIdentified) << at9.detail;
      EXPECT_EQ(at9.identity.product_code, profiles::cdn127::kProductCode);
    }
  }
  loop.stop();
  loop.join();

  RecordingPublisher offline;
  PortLoop absent(config_for({1}),
                  std::make_unique<UnpluggedBackend>(std::make_unique<sim::SimBackend>(
                      can::kBitrate500k, std::vector<MacId>{mac(1)})),
                  offline, null_log_sink());
  absent.start();
  ASSERT_TRUE(offline.wait_for([&] { return offline.port_samples >= 1; }));
  absent.scan_request({"third", 3});
  ASSERT_TRUE(offline.wait_for([&] { return !offline.scans.empty(); }));
  {
    std::lock_guard lock(offline.mutex());
    EXPECT_EQ(offline.scans[0].status, rack::TransactionStatus::kPortOffline);
    EXPECT_NE(offline.scans[0].message.find("the bus is interface down: no bus scan"),
              std::string::npos)
        << offline.scans[0].message;
    EXPECT_TRUE(offline.scans[0].findings.empty());
  }
  absent.stop();
  absent.join();
}

}  // namespace
}  // namespace dnbridge::port

namespace dnbridge::port {
namespace {

// A configuration read again reaches the port's thread: the removed node's
// instances go, the added one is published and commanded, the explicit
// policy and the publish policies follow; a refused scan list changes
// nothing and says why.
TEST(PortLoop, AReconfigurationIsAppliedOnThePortsThread) {
  RecordingPublisher publisher;
  PortLoop loop(config_for({1, 2}),
                std::make_unique<sim::SimBackend>(can::kBitrate500k,
                                                  std::vector<MacId>{mac(1), mac(2), mac(3)}),
                publisher, null_log_sink());
  loop.start();
  ASSERT_TRUE(
      publisher.wait_for([&] { return publisher.port && publisher.port->nodes_online == 2; }));
  EXPECT_FALSE(loop.has_node(mac(3)));

  PortLoopConfig next = config_for({1, 3});
  next.publish[mac(1)].max_period = milliseconds(300);
  next.explicit_policy.allow_output_writes = true;
  auto done = loop.reconfigure(next);
  ASSERT_EQ(done.wait_for(std::chrono::seconds(10)), std::future_status::ready);
  const PortChange change = done.get();
  EXPECT_TRUE(change.refused.empty()) << change.refused;
  EXPECT_EQ(change.scan_list.added, std::vector<MacId>{mac(3)});
  EXPECT_EQ(change.scan_list.removed, std::vector<MacId>{mac(2)});
  EXPECT_EQ(change.scan_list.unchanged, std::vector<MacId>{mac(1)});
  EXPECT_EQ(change.publish_changed, std::vector<MacId>{mac(1)});
  EXPECT_TRUE(change.explicit_policy_changed);
  EXPECT_TRUE(loop.has_node(mac(3)));
  EXPECT_FALSE(loop.has_node(mac(2)));
  EXPECT_EQ(loop.nodes_configured(), 2u);

  ASSERT_TRUE(publisher.wait_for([&] {
    return publisher.removed == std::vector<unsigned>{2} && publisher.pumps.count(3) &&
           publisher.pumps[3].online && publisher.port->nodes_online == 2 &&
           publisher.port->nodes_configured == 2;
  }));
  profiles::cdn127::PumpOutputs out;
  out.pump_on = true;
  loop.command(mac(3), rack::NodeCommand(out), "supervisor-1");
  ASSERT_TRUE(publisher.wait_for([&] { return !publisher.pumps[3].outputs_idle; }));
  // Node 2 was idled and released (two exchanges, begun before node 3's
  // first Allocate), not left to its connections' watchdogs.
  std::promise<std::pair<bool, bool>> released;
  loop.post([&](CanBackend& b) {
    const auto& d = static_cast<sim::SimBackend&>(b).device(mac(2)).device();
    released.set_value({d.poll_state() != sim::ConnectionState::kEstablished,
                        d.explicit_state() != sim::ConnectionState::kEstablished});
  });
  EXPECT_EQ(released.get_future().get(), std::make_pair(true, true));

  // A node at the master's MAC: refused whole.
  auto refused = loop.reconfigure(config_for({0, 1, 3}));
  ASSERT_EQ(refused.wait_for(std::chrono::seconds(10)), std::future_status::ready);
  const PortChange none = refused.get();
  EXPECT_NE(none.refused.find("master's MAC"), std::string::npos) << none.refused;
  EXPECT_FALSE(loop.has_node(mac(0)));
  EXPECT_TRUE(loop.has_node(mac(3)));
  loop.stop();
  loop.join();
}

}  // namespace
}  // namespace dnbridge::port

namespace dnbridge::port {
namespace {

// A node added in the middle of the file is added last to the rack; what is
// published of each pump stays the pump's through later reloads.
TEST(PortLoop, APumpKeepsItsPublishStateThroughReloadsWhateverTheOrder) {
  RecordingPublisher publisher;
  PortLoopConfig first = config_for({1, 3});
  first.publish[mac(1)].max_period = milliseconds(500);
  first.publish[mac(3)].max_period = milliseconds(400);
  PortLoop loop(first,
                std::make_unique<sim::SimBackend>(can::kBitrate500k,
                                                  std::vector<MacId>{mac(1), mac(2), mac(3)}),
                publisher, null_log_sink());
  loop.start();
  PortLoopConfig second = config_for({1, 2, 3});
  second.publish[mac(1)].max_period = milliseconds(500);
  second.publish[mac(2)].max_period = milliseconds(600);
  second.publish[mac(3)].max_period = milliseconds(400);
  const auto apply = [&](const PortLoopConfig& c) {
    auto done = loop.reconfigure(c);
    EXPECT_EQ(done.wait_for(std::chrono::seconds(10)), std::future_status::ready);
    return done.get();
  };
  const PortChange added = apply(second);
  EXPECT_EQ(added.scan_list.added, std::vector<MacId>{mac(2)});
  EXPECT_TRUE(added.publish_changed.empty());
  // The same again: nothing differs, for any pump.
  const PortChange again = apply(second);
  EXPECT_FALSE(again.any()) << again.publish_changed.size();
  // One pump's policy: that pump's only.
  second.publish[mac(3)].max_period = milliseconds(300);
  const PortChange one = apply(second);
  EXPECT_EQ(one.publish_changed, std::vector<MacId>{mac(3)});
  loop.stop();
  loop.join();
}

}  // namespace
}  // namespace dnbridge::port
