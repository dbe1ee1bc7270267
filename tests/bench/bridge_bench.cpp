// dnbridge-bench: what the bridge costs in latency and CPU, beside what Cyclone
// DDS itself costs on the same machine in the same run.
//
//   (0) Cyclone's own one-way latency: ddsperf ping and pong (two processes,
//       waitset mode, on loopback), one-way = round trip / 2 (ddsperf prints
//       its round trips halved already), run beside each latency
//       measurement below, over the same seconds.
//   (0b) Cyclone alone on the path of a command: PumpCommands written by the
//       commander process, taken here, nothing behind it, twice: on a
//       waitset thread, and by a listener on Cyclone's thread (as the bridge
//       takes them); one way, measured on CLOCK_MONOTONIC at both ends. The
//       bridge's own addition to (2) is measured against the listener's.
//   (0c) Cyclone alone on the state path: PumpStates written in this process
//       with the bridge's QoS, in the pattern of (1)'s poll responses, taken
//       by the subscriber process as in (1); the bridge's own addition to (1)
//       is measured against it.
//   (0d) one thread of this process waking another on the same CPU, nothing
//       else running: the one hand-over each of (1) and (2) makes.
//   (1) poll response received by the master -> PumpState taken by a
//       subscriber in another process: wall clock at take - source timestamp
//       (the bridge stamps each sample with the CAN receive time of the poll
//       response it comes from). Split sample by sample (matched by node and
//       analog value): the response's way to the port's thread (the CAN
//       controller waking it), and from there to the take.
//   (2) PumpCommand written in another process -> the poll frame carrying the
//       new outputs, written by the master to its CAN interface, and its start
//       of frame on the simulated bus (after any frame already on the wire
//       and arbitration): both ends on CLOCK_MONOTONIC, which the two
//       processes share. Commands come at random gaps, so that they meet the
//       poll schedule at every phase. (1) and (2) are measured with polls
//       every 10 ms and every 100 ms (the shipped default). Commands that
//       meet a poll in flight: from its response to the new poll written.
//       The others split: until the port's thread woke for the command, and
//       from there to the frame written; the first again at the wake-up the
//       bridge's listener asks for (the end of its work on Cyclone's
//       thread), which leaves the hand-over to the port's thread alone.
//   (3) CPU time of the bridge per second of wall time, 4 ports x 63 nodes
//       polled every 10 ms, the simulated devices' threads left out; (3b)
//       the same with a PumpState per poll; (3c) Cyclone alone writing (3b)'s
//       samples, CPU per sample, which splits (3b)'s cost per sample into
//       Cyclone's write and the bridge's own work; (3d) (3c) with Cyclone's
//       write batching.
//
// The bridge runs in this process (daemon::Daemon, configuration built here,
// each port on a ThreadedSimBackend: the simulated bus and devices on a
// thread of their own). The subscriber and commander is this same program
// re-executed with --client: another process, another DDS participant. Every
// DDS participant of the run, ddsperf's included, is pinned to the loopback
// interface with a discovery tag of this run's own. The measured process
// (this one; ddsperf pong) and its peer (the client; ddsperf ping) each run
// on a CPU of their own, and CPUs are held out of idle halts for the run
// (see --help to change either).
//
// It reports figures; it exits non-zero only when the run itself fails.
#include <fmt/format.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/daemon.hpp"
#include "adapters/daemon/log_sink.hpp"
#include "adapters/dds/fields.hpp"
#include "adapters/dds/listener.hpp"
#include "adapters/dds/loopback.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/sim/world/threaded_sim_backend.hpp"
#include "bench_process.hpp"
#include "bridge/can/can_timing.hpp"
#include "bridge/devicenet/wire/identifier.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"
#include "ddsperf.hpp"
#include "figures.hpp"

namespace dnbridge::bench {
namespace {

using devicenet::MacId;

// ---------------------------------------------------------------------------
// Clocks

std::int64_t process_cpu_ns() { return clock_ns(CLOCK_PROCESS_CPUTIME_ID); }
std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The bridge's receive and frame times are std::chrono::steady_clock (the
// simulated bus runs on it); the commander stamps its writes with
// clock_gettime(CLOCK_MONOTONIC). They are one clock if every steady_clock
// reading falls between two CLOCK_MONOTONIC readings taken around it.
bool steady_clock_is_monotonic() {
  for (int i = 0; i < 1000; ++i) {
    const auto a = monotonic_ns();
    const auto s = steady_ns();
    const auto b = monotonic_ns();
    if (s < a || s > b) return false;
  }
  return true;
}

// Where the process's CPU time goes, thread by thread (/proc: clock ticks,
// and context switches, i.e. how often each thread slept and was woken or was
// preempted).
struct ThreadSample {
  std::string name;
  double cpu_s = 0;
  std::uint64_t switches = 0;
};

std::map<pid_t, ThreadSample> snapshot_threads() {
  std::map<pid_t, ThreadSample> out;
  const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) {
    const auto tid = static_cast<pid_t>(std::stol(entry.path().filename().string()));
    ThreadSample t;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    std::getline(stat, line);
    const auto open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos) continue;
    t.name = line.substr(open + 1, close - open - 1);
    std::istringstream rest(line.substr(close + 2));
    std::vector<std::string> fields{std::istream_iterator<std::string>(rest), {}};
    if (fields.size() < 13) continue;
    // Fields 14 and 15 of the line (utime, stime) are 12 and 13 after the name.
    t.cpu_s = (std::stod(fields[11]) + std::stod(fields[12])) / tick;
    std::ifstream status(entry.path() / "status");
    while (std::getline(status, line)) {
      if (line.rfind("voluntary_ctxt_switches:", 0) == 0 ||
          line.rfind("nonvoluntary_ctxt_switches:", 0) == 0) {
        t.switches += std::stoull(line.substr(line.find(':') + 1));
      }
    }
    out[tid] = t;
  }
  return out;
}

pid_t this_thread_id() { return static_cast<pid_t>(gettid()); }

// ---------------------------------------------------------------------------
// DDS set-up shared by every process of the run

constexpr const char* kRack = "bench";

// ---------------------------------------------------------------------------
// The client process: subscriber and commander

struct ClientOptions {
  std::string mode;  // "latency" or "count"
  int domain = 0;
  std::vector<std::string> ports;
  unsigned nodes = 0;           // MACs 1..nodes on each port
  double seconds = 0;           // measurement window after every node is online
  int command_interval_us = 0;  // latency: one command every so often
  bool command_once = false;    // count: one command per node at the start
};

int run_client(const ClientOptions& o) {
  dds::Participant participant(static_cast<dds_domainid_t>(o.domain), "bench-client");
  dds::Topic<dnbridge_PumpState> state_topic(participant);
  dds::Topic<dnbridge_PumpCommand> command_topic(participant);
  dds::Reader<dnbridge_PumpState> reader(participant, state_topic, dds::state_reader_qos());
  dds::Writer<dnbridge_PumpCommand> writer(
      participant, command_topic,
      dds::command_writer_qos(dds::rack_partitions(kRack), 10, seconds(5)));
  dds::ReadCondition any(reader, DDS_ANY_STATE);
  dds::GuardCondition stop(participant);
  dds::WaitSet waitset(participant);
  waitset.attach(any, 1);
  waitset.attach(stop, 2);

  // "oneway": no bridge, only a reader of the commands to match. "state": no
  // bridge, PumpStates written by the benchmark with the bridge's QoS, and
  // no command reader to match.
  const bool commanding = o.mode == "latency" || o.mode == "oneway";
  const bool state_latency = o.mode == "latency" || o.mode == "state";
  const bool command_reader = o.mode != "state";
  const std::size_t expected = o.mode == "oneway" ? 0 : o.ports.size() * o.nodes;
  auto key_of = [&](const dnbridge_PumpState& s) -> std::optional<std::size_t> {
    for (std::size_t p = 0; p < o.ports.size(); ++p) {
      if (dds::view(s.port) == o.ports[p] && s.mac >= 1 && s.mac <= o.nodes) {
        return p * 64 + s.mac;
      }
    }
    return std::nullopt;
  };

  std::atomic<std::size_t> ready_count{0};
  std::atomic<bool> measuring{false};
  std::atomic<std::uint64_t> taken{0};
  // Each new poll response's sample: its latency, key and analog input
  // (with which the benchmark finds the response it came from).
  struct StateLatency {
    std::int64_t ns;
    std::size_t key;
    int analog;
  };
  std::vector<StateLatency> latencies;  // reader thread until joined
  latencies.reserve(200000);

  std::thread taker([&] {
    std::vector<char> ready(o.ports.size() * 64, 0);
    std::vector<int> last_analog(o.ports.size() * 64, -1);
    std::size_t ready_n = 0;
    for (;;) {
      auto triggered = waitset.wait(milliseconds(200));
      if (!triggered) continue;
      bool stopping = false;
      for (auto t : *triggered) stopping = stopping || t == 2;
      if (stopping) return;
      // Few at a time: Reader::take allocates `max` samples and frees the
      // unused ones, a cost that would be counted in the latency.
      auto samples = reader.take(any, 8);
      const auto now = dds::dds_now();
      if (!samples) continue;
      const bool counting = measuring.load(std::memory_order_relaxed);
      for (const auto& s : *samples) {
        if (!s.valid_data()) continue;
        const auto& d = s.data();
        const auto key = key_of(d);
        if (!key) continue;
        const bool is_ready = d.online && d.inputs_valid;
        if (is_ready != static_cast<bool>(ready[*key])) {
          ready[*key] = is_ready;
          ready_n = is_ready ? ready_n + 1 : ready_n - 1;
          ready_count.store(ready_n);
        }
        const int analog = d.analog_input_count > 0 ? d.analog_input_raw[0] : -1;
        const bool fresh = analog != last_analog[*key];
        last_analog[*key] = analog;
        if (!counting) continue;
        taken.fetch_add(1, std::memory_order_relaxed);
        // A new analog value: the sample of a new poll response.
        if (state_latency && is_ready && fresh) {
          latencies.push_back({(now - s.info().source_timestamp()).count(), *key, analog});
        }
      }
    }
  });

  auto fail = [&](const char* what) {
    std::fprintf(stderr, "dnbridge-bench client: %s\n", what);
    (void)stop.trigger();
    taker.join();
    return 1;
  };

  // Every node online and its inputs read, and the bridge's command reader matched.
  const auto online_deadline = monotonic_ns() + 90'000'000'000;
  while (ready_count.load() < expected ||
         (command_reader && writer.matched_subscriptions().value_or(0) == 0)) {
    if (monotonic_ns() > online_deadline) return fail("not every node came online within 90 s");
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::printf("ready\n");
  std::fflush(stdout);

  struct Written {
    unsigned mac;
    unsigned value;
    std::int64_t at;
  };
  std::vector<Written> written;
  auto command = [&](const std::string& port, unsigned mac, bool pump_on, unsigned value) {
    dds::Owned<dnbridge_PumpCommand> c;
    dds::set_string(c->rack, kRack);
    dds::set_string(c->port, port);
    c->mac = static_cast<std::uint8_t>(mac);
    c->pump_on = pump_on;
    c->n2_ballast_on = false;
    c->analog_output_raw = static_cast<std::uint16_t>(value);
    dds::set_string(c->issuer, "dnbridge-bench");
    // The write time, on CLOCK_MONOTONIC; the sample's source timestamp is
    // Cyclone's wall clock at the same moment.
    const auto at = monotonic_ns();
    if (!writer.write(*c)) return false;
    written.push_back({mac, value, at});
    return true;
  };

  const auto start = monotonic_ns();
  const auto window = static_cast<std::int64_t>(o.seconds * 1e9);
  measuring = true;
  if (commanding) {
    // Round robin over the nodes of the first port; each command a new
    // analog output value for its node (1..4095), so that the poll frame
    // that carries it is known by its value. The gaps are drawn uniformly
    // from 0.5..1.5 x the interval (fixed seed): commands at a fixed period
    // would meet the bridge's poll schedule, which has the same period, at
    // one phase for the whole run, and measure that phase only.
    std::vector<unsigned> value(64, 0);
    const auto interval = static_cast<std::int64_t>(o.command_interval_us) * 1000;
    std::mt19937_64 random(20261122);
    std::uniform_int_distribution<std::int64_t> gap(interval / 2, interval + interval / 2);
    std::int64_t next = start;
    for (unsigned i = 0; monotonic_ns() < start + window; ++i) {
      const unsigned mac = 1 + i % o.nodes;
      value[mac] = value[mac] % 4095 + 1;
      if (!command(o.ports[0], mac, false, value[mac])) return fail("writing a PumpCommand failed");
      next += gap(random);
      sleep_until_monotonic(next);
    }
    sleep_until_monotonic(monotonic_ns() + 300'000'000);  // the last commands' polls
  } else {
    if (o.command_once) {
      for (const auto& port : o.ports) {
        for (unsigned mac = 1; mac <= o.nodes; ++mac) {
          if (!command(port, mac, true, 2048)) return fail("writing a PumpCommand failed");
        }
      }
    }
    sleep_until_monotonic(start + window);
  }
  measuring = false;
  const auto elapsed = monotonic_ns() - start;
  (void)stop.trigger();
  taker.join();

  // "taken" first: the benchmark ends a CPU window on it, before it reads
  // the rest.
  std::string out;
  out.reserve(latencies.size() * 24 + written.size() * 32 + 256);
  out += fmt::format("taken {} {}\n", taken.load(), elapsed);
  for (const auto& l : latencies) out += fmt::format("state {} {} {}\n", l.ns, l.key, l.analog);
  if (commanding) {
    for (const auto& w : written) out += fmt::format("cmd {} {} {}\n", w.mac, w.value, w.at);
  }
  out += "done\n";
  std::fwrite(out.data(), 1, out.size(), stdout);
  std::fflush(stdout);
  return 0;
}

// ---------------------------------------------------------------------------
// The bridge side

// What the bus tap of one port sees, on that port's world thread, and what
// its master writes and is handed, on the port's thread.
struct PortWire {
  sim::ThreadedSimBackend* backend = nullptr;
  std::uint32_t bitrate = 0;
  bool ramp = false;            // a new analog input value before every poll
  bool record_outputs = false;  // the first poll frame of each new output value
  std::size_t index = 0;        // the port's place in the setup (the subscriber's keys)
  profiles::cdn127::PollRequestLayout request_layout;
  profiles::cdn127::PollResponseLayout response_layout;
  std::array<std::uint16_t, 64> ramp_value{};
  std::array<int, 64> last_output{};
  std::atomic<std::uint64_t> polls{0};
  std::atomic<std::uint64_t> responses{0};

  struct OutputFrame {
    unsigned mac;
    unsigned value;
    std::int64_t start;  // on the wire: start and end of frame, steady clock
    std::int64_t end;
  };
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
  // A poll response and when the port's thread had it. `slept`: the thread
  // was waiting when the response was received and this was the first
  // frame it was handed: the receive time to `handed` is then its wake-up
  // by the CAN controller (here, the simulated bus's thread) alone.
  struct HandedResponse {
    can::CanFrame frame;
    std::size_t key;  // port index * 64 + MAC, as the subscriber's
    std::int64_t rx;
    std::int64_t handed;
    bool slept;
  };
  std::mutex mutex;
  std::vector<OutputFrame> output_frames;
  std::vector<WrittenFrame> written_frames;
  std::vector<HandedResponse> handed_responses;  // the port's thread; read once it stopped
  std::array<int, 64> last_written{};

  // The MAC and analog output of a poll request carrying outputs.
  std::optional<std::pair<unsigned, unsigned>> output_of(const can::CanFrame& frame) const {
    const auto id = devicenet::decode_identifier(frame.id);
    if (!id || id->group != devicenet::MessageGroup::k2 ||
        id->message_id != static_cast<std::uint8_t>(devicenet::Group2Message::kMasterIoPoll) ||
        frame.len == 0) {
      return std::nullopt;
    }
    auto outputs = profiles::cdn127::decode_poll_request(request_layout, frame.payload());
    if (!outputs) return std::nullopt;
    return std::make_pair(unsigned{id->mac.value()}, unsigned{outputs->analog_out_raw});
  }

  // On the port's thread: the first poll frame of each new output value, as
  // the master writes it, stamped when it is written (the time the master
  // hands with it is its loop's time, which can be earlier).
  void on_written(const can::CanFrame& frame) {
    if (!record_outputs) return;
    const auto at = steady_ns();
    const auto out = output_of(frame);
    if (!out || static_cast<int>(out->second) == last_written[out->first]) return;
    last_written[out->first] = static_cast<int>(out->second);
    std::lock_guard lock(mutex);
    const bool after_response = static_cast<int>(out->first) == answering_mac;
    written_frames.push_back({out->first, out->second, at, after_response,
                              after_response ? answering_rx : 0, waiting_since, woke, woken_by});
  }

  // On the port's thread: the MAC whose poll response the master is being
  // handed, while it is (-1 otherwise). A frame written then was sent in
  // answer to it.
  int answering_mac = -1;
  std::int64_t answering_rx = 0;
  void on_receiving(const can::CanFrame& frame, TimePoint rx_time) {
    const auto id = devicenet::decode_identifier(frame.id);
    const bool response =
        id && id->group == devicenet::MessageGroup::k1 &&
        id->message_id == static_cast<std::uint8_t>(devicenet::Group1Message::kSlavePollResponse);
    answering_mac = response ? id->mac.value() : -1;
    answering_rx = rx_time.time_since_epoch().count();
  }
  void on_received() { answering_mac = -1; }

  // On the port's thread: when it began its last wait, and when it ran
  // again after it (a frame handed to it, or the wait's return). Kept short:
  // it runs inside the paths measured.
  std::int64_t waiting_since = 0;
  std::int64_t woke = 0;
  std::int64_t woken_by = 0;
  // Written by whichever thread wakes the port's loop.
  std::atomic<std::int64_t> last_wake{0};
  void on_waiting() {
    woke = 0;
    waiting_since = steady_ns();
  }
  void on_wake() { last_wake.store(steady_ns(), std::memory_order_relaxed); }
  // True the first time after a wait.
  bool on_running() {
    if (woke != 0) return false;
    woke = steady_ns();
    const auto wake = last_wake.load(std::memory_order_relaxed);
    woken_by = wake >= waiting_since ? wake : 0;
    return true;
  }
  void on_response(const can::CanFrame& frame, std::int64_t rx, bool first) {
    const auto handed = first ? woke : steady_ns();
    handed_responses.push_back({frame, index * 64 + static_cast<unsigned>(answering_mac), rx,
                                handed, first && waiting_since <= rx});
  }
  // The analog input of a poll response; none if it carries none.
  std::optional<unsigned> analog_input(const can::CanFrame& frame) const {
    const auto inputs = profiles::cdn127::decode_poll_response(response_layout, 0, frame.payload());
    if (!inputs || !inputs->analog_inputs_raw[0]) return std::nullopt;
    return *inputs->analog_inputs_raw[0];
  }

  void on_wire(const sim::WireFrame& wf) {
    const auto id = devicenet::decode_identifier(wf.frame.id);
    if (!id) return;
    if (id->group == devicenet::MessageGroup::k1 &&
        id->message_id == static_cast<std::uint8_t>(devicenet::Group1Message::kSlavePollResponse)) {
      responses.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    if (id->group != devicenet::MessageGroup::k2 ||
        id->message_id != static_cast<std::uint8_t>(devicenet::Group2Message::kMasterIoPoll)) {
      return;
    }
    polls.fetch_add(1, std::memory_order_relaxed);
    const unsigned mac = id->mac.value();
    if (ramp) {
      // The tap runs before any node receives the frame: the device answers
      // this poll with the new value, so every poll response is a change.
      ramp_value[mac] = static_cast<std::uint16_t>((ramp_value[mac] + 1) % 4096);
      (void)backend->device(id->mac).device().pump().set_analog_input(0, ramp_value[mac]);
    }
    if (!record_outputs) return;
    if (const auto out = output_of(wf.frame);
        out && static_cast<int>(out->second) != last_output[mac]) {
      last_output[mac] = static_cast<int>(out->second);
      const auto end = wf.end.time_since_epoch().count();
      const auto start = end - can::frame_duration(wf.frame, bitrate).count();
      std::lock_guard lock(mutex);
      output_frames.push_back({mac, out->second, start, end});
    }
  }
};

// The port's CAN interface as its master sees it, noting the poll frames it
// writes (PortWire::on_written): where the bridge's own part of (2) ends and
// the bus's (waiting for a frame already on the wire, arbitration) begins.
class WrittenFramesBackend final : public port::CanBackend {
 public:
  WrittenFramesBackend(std::unique_ptr<sim::ThreadedSimBackend> inner, PortWire& wire)
      : inner_(std::move(inner)), wire_(wire), sink_(inner_->sink(), wire) {}

  can::FrameSink& sink() override { return sink_; }
  TimePoint now() const override { return inner_->now(); }
  void wait(TimePoint deadline, port::FrameReceiver& receiver) override {
    wire_.on_waiting();
    Receiver noting{receiver, wire_};
    inner_->wait(deadline, noting);
    (void)wire_.on_running();
  }
  void wake() override {
    wire_.on_wake();
    inner_->wake();
  }
  port::BusCounters counters() const override { return inner_->counters(); }
  std::string interface_name() const override { return inner_->interface_name(); }
  std::uint32_t bitrate() const override { return inner_->bitrate(); }

 private:
  class Sink final : public can::FrameSink {
   public:
    Sink(can::FrameSink& inner, PortWire& wire) : inner_(inner), wire_(wire) {}
    void send(const can::CanFrame& frame, TimePoint now) override {
      wire_.on_written(frame);
      inner_.send(frame, now);
    }

   private:
    can::FrameSink& inner_;
    PortWire& wire_;
  };
  class Receiver final : public port::FrameReceiver {
   public:
    Receiver(port::FrameReceiver& inner, PortWire& wire) : inner_(inner), wire_(wire) {}
    void on_frame(const can::CanFrame& frame, TimePoint rx_time) override {
      const bool first = wire_.on_running();
      wire_.on_receiving(frame, rx_time);
      if (wire_.answering_mac >= 0) {
        wire_.on_response(frame, rx_time.time_since_epoch().count(), first);
      }
      inner_.on_frame(frame, rx_time);
      wire_.on_received();
    }

   private:
    port::FrameReceiver& inner_;
    PortWire& wire_;
  };
  std::unique_ptr<sim::ThreadedSimBackend> inner_;
  PortWire& wire_;
  Sink sink_;
};

struct BridgeSetup {
  std::vector<std::string> ports;
  unsigned nodes = 0;
  std::uint32_t bitrate = can::kBitrate500k;
  Duration poll_period = milliseconds(10);
  rack::PublishPolicy publish;
  bool ramp = false;
  bool record_outputs = false;
};

class Bridge {
 public:
  Bridge(const BridgeSetup& s, int domain, LogSink& log) {
    daemon::DaemonConfig c;
    c.rack = kRack;
    c.domain_id = static_cast<std::uint32_t>(domain);
    c.master_mac = MacId::from(0).value();
    c.log_level = LogLevel::kWarn;
    c.source = "dnbridge-bench";
    for (const auto& name : s.ports) {
      daemon::PortConfig p;
      p.name = name;
      p.interface = std::string(daemon::kSimulatedInterface);
      p.bitrate = s.bitrate;
      p.master.master_mac = c.master_mac;
      for (unsigned m = 1; m <= s.nodes; ++m) {
        daemon::NodeSettings n;
        n.pump.node.mac = MacId::from(m).value();
        n.pump.node.name = fmt::format("pump-{}-{}", name, m);
        n.pump.node.poll_period = s.poll_period;
        n.publish = s.publish;
        p.nodes.push_back(n);
      }
      c.ports.push_back(std::move(p));
    }
    const auto format =
        profiles::cdn127::poll_format(
            profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn127))
            .value();
    auto factory = [this, &s, &log,
                    format](const daemon::PortConfig& p) -> std::unique_ptr<port::CanBackend> {
      std::vector<MacId> macs;
      for (const auto& n : p.nodes) macs.push_back(n.pump.node.mac);
      auto backend = std::make_unique<sim::ThreadedSimBackend>(p.bitrate, macs, &log);
      auto wire = std::make_unique<PortWire>();
      wire->backend = backend.get();
      wire->bitrate = p.bitrate;
      wire->ramp = s.ramp;
      wire->record_outputs = s.record_outputs;
      wire->index = static_cast<std::size_t>(std::find(s.ports.begin(), s.ports.end(), p.name) -
                                             s.ports.begin());
      wire->request_layout = format.request;
      wire->response_layout = format.response;
      wire->last_output.fill(-1);
      wire->last_written.fill(-1);
      wire->handed_responses.reserve(1 << 18);
      PortWire* w = wire.get();
      auto* b = backend.get();
      backend->post(
          [w, b] { b->world().bus().set_tap([w](const sim::WireFrame& f) { w->on_wire(f); }); });
      backends_.push_back(b);
      wires_.push_back(std::move(wire));
      if (!s.record_outputs) return backend;
      return std::make_unique<WrittenFramesBackend>(std::move(backend), *w);
    };
    daemon_ = std::make_unique<daemon::Daemon>(std::move(c), log, factory);
  }
  ~Bridge() { stop(); }

  void start() { daemon_->start(); }
  void stop() {
    if (daemon_) daemon_->stop();
  }

  // The simulated worlds' threads, together.
  std::int64_t sim_cpu_ns() const {
    std::int64_t t = 0;
    for (auto* b : backends_) t += b->sim_thread_cpu_time().count();
    return t;
  }
  std::uint64_t polls() const {
    std::uint64_t n = 0;
    for (const auto& w : wires_) n += w->polls.load();
    return n;
  }
  std::uint64_t responses() const {
    std::uint64_t n = 0;
    for (const auto& w : wires_) n += w->responses.load();
    return n;
  }
  std::uint64_t bus_bits() const {
    std::uint64_t n = 0;
    for (auto* b : backends_) n += b->counters().bits;
    return n;
  }
  // The threads of the ports' loops and of the simulated worlds.
  std::set<pid_t> port_threads() {
    std::set<pid_t> tids;
    for (const auto& p : daemon_->config().ports) {
      std::promise<pid_t> tid;
      daemon_->port(p.name)->post([&tid](port::CanBackend&) { tid.set_value(this_thread_id()); });
      tids.insert(tid.get_future().get());
    }
    return tids;
  }
  std::set<pid_t> sim_threads() {
    std::set<pid_t> tids;
    for (auto* b : backends_) {
      std::promise<pid_t> tid;
      b->post([&tid] { tid.set_value(this_thread_id()); });
      tids.insert(tid.get_future().get());
    }
    return tids;
  }

  std::vector<PortWire::OutputFrame> output_frames() { return gather(&PortWire::output_frames); }
  std::vector<PortWire::WrittenFrame> written_frames() { return gather(&PortWire::written_frames); }
  // Every poll response handed to a port's thread: its key and analog
  // value, from its receive time to the thread having it (ns), and whether
  // that was the thread's wake-up for it (PortWire::HandedResponse::slept).
  // Once the bridge has stopped.
  struct Handed {
    std::size_t key;
    unsigned value;
    std::int64_t ns;
    bool slept;
  };
  std::vector<Handed> handed_responses() {
    std::vector<Handed> all;
    for (const auto& w : wires_) {
      for (const auto& h : w->handed_responses) {
        if (const auto value = w->analog_input(h.frame)) {
          all.push_back({h.key, *value, h.handed - h.rx, h.slept});
        }
      }
    }
    return all;
  }

 private:
  // One record of every port's wire, in port order.
  template <class Frame>
  std::vector<Frame> gather(std::vector<Frame> PortWire::*record) {
    std::vector<Frame> all;
    for (auto& w : wires_) {
      std::lock_guard lock(w->mutex);
      const auto& frames = (*w).*record;
      all.insert(all.end(), frames.begin(), frames.end());
    }
    return all;
  }

  std::vector<sim::ThreadedSimBackend*> backends_;
  std::vector<std::unique_ptr<PortWire>> wires_;  // outlive the daemon (its backends' taps)
  std::unique_ptr<daemon::Daemon> daemon_;
};

struct Options {
  int ddsperf_rate = 500;
  int ddsperf_size = 128;
  double latency_seconds = 25;
  double direct_seconds = 15;
  std::vector<int> latency_poll_ms{10, 100};
  unsigned latency_nodes = 8;
  int command_interval_ms = 10;
  double cpu_seconds = 20;
  double busy_seconds = 10;
  int domain = -1;
  bool pin = true;
  bool hold_awake = true;
  int bridge_cpu = 1;
  int peer_cpu = 0;
};

std::vector<std::string> client_args(const std::string& mode, int domain,
                                     const std::vector<std::string>& ports, unsigned nodes,
                                     double seconds) {
  std::string port_list;
  for (const auto& p : ports) port_list += (port_list.empty() ? "" : ",") + p;
  return {"/proc/self/exe",
          "--client",
          mode,
          "--domain",
          std::to_string(domain),
          "--ports",
          port_list,
          "--nodes",
          std::to_string(nodes),
          "--seconds",
          fmt::format("{}", seconds)};
}

// Reads a client's output to its end; its "ready" line (every node online)
// calls `on_ready`, its "taken" line (end of its window) `on_end`.
struct ClientOutput {
  std::vector<double> state_us;
  // The same, with the sample's key and analog input.
  struct State {
    double us;
    std::size_t key;
    unsigned value;
  };
  std::vector<State> states;
  struct Cmd {
    unsigned mac, value;
    std::int64_t at;
  };
  std::vector<Cmd> commands;
  std::uint64_t taken = 0;
  double window_s = 0;
  bool done = false;
};

template <class OnReady, class OnEnd>
ClientOutput read_client(Child child, double seconds, OnReady on_ready, OnEnd on_end) {
  ClientOutput out;
  LineReader lines(child.out);
  const auto deadline = monotonic_ns() + static_cast<std::int64_t>((seconds + 150) * 1e9);
  while (auto line = lines.next(deadline)) {
    if (*line == "ready") {
      on_ready();
    } else if (line->rfind("state ", 0) == 0) {
      long long ns = 0;
      std::size_t key = 0;
      int value = -1;
      if (std::sscanf(line->c_str(), "state %lld %zu %d", &ns, &key, &value) == 3) {
        out.state_us.push_back(static_cast<double>(ns) / 1e3);
        if (value >= 0)
          out.states.push_back({out.state_us.back(), key, static_cast<unsigned>(value)});
      }
    } else if (line->rfind("cmd ", 0) == 0) {
      ClientOutput::Cmd c{};
      long long at = 0;
      if (std::sscanf(line->c_str(), "cmd %u %u %lld", &c.mac, &c.value, &at) == 3) {
        c.at = at;
        out.commands.push_back(c);
      }
    } else if (line->rfind("taken ", 0) == 0) {
      on_end();
      unsigned long long n = 0;
      long long ns = 0;
      if (std::sscanf(line->c_str(), "taken %llu %lld", &n, &ns) == 2) {
        out.taken = n;
        out.window_s = static_cast<double>(ns) / 1e9;
      }
    } else if (*line == "done") {
      out.done = true;
    }
  }
  if (lines.timed_out()) kill(child.pid, SIGKILL);
  close(child.out);
  const int status = wait_child(child.pid);
  if (status != 0 || !out.done) {
    throw std::runtime_error(fmt::format("the client process failed (exit {})", status));
  }
  return out;
}

std::string us(double v) { return fmt::format("{:.1f} us", v); }

// How (0b) takes the commands.
enum class Taker {
  kWaitset,   // a waitset on a thread of its own
  kListener,  // a DATA_AVAILABLE listener, on Cyclone's delivering thread (as the bridge does)
};

// Cyclone DDS alone on the path of a command: the commander process writes
// PumpCommands as in (2), at the same gaps, with the same QoS, and a reader
// in this process takes them (`taker`), with nothing behind it. Write
// (CLOCK_MONOTONIC in the commander) -> take (CLOCK_MONOTONIC here): one
// way, measured, not halved from a round trip.
template <class OnReady>
std::vector<double> direct_oneway(int domain, Placement cpus, double seconds, int interval_us,
                                  unsigned nodes, Taker taker_kind, OnReady on_ready) {
  dds::Participant participant(static_cast<dds_domainid_t>(domain), "bench-direct");
  dds::Topic<dnbridge_PumpCommand> topic(participant);
  std::map<std::pair<unsigned, unsigned>, std::int64_t> taken_at;
  std::optional<dds::Reader<dnbridge_PumpCommand>> reader;
  const auto take = [&] {
    auto samples = reader->take();
    const auto now = monotonic_ns();
    if (!samples) return;
    for (const auto& sample : *samples) {
      if (!sample.info().valid_data()) continue;
      taken_at.emplace(
          std::make_pair(unsigned{sample.data().mac}, unsigned{sample.data().analog_output_raw}),
          now);
    }
  };
  // The listener's calls come on one Cyclone thread; detached (every call
  // over) before taken_at is read.
  dds::DataListener listener([&] { take(); });
  const auto qos = dds::command_reader_qos(dds::rack_partitions(kRack));
  if (taker_kind == Taker::kListener) {
    reader.emplace(participant, topic, qos, listener.get());
  } else {
    reader.emplace(participant, topic, qos);
  }
  // Detached before the listener goes, whichever way this returns.
  struct Detach {
    const dds::Entity& reader;
    ~Detach() { (void)dds::DataListener::detach(reader); }
  } detach{*reader};
  if (!reader->set_status_mask(DDS_DATA_AVAILABLE_STATUS)) {
    throw std::runtime_error("setting the reader's status mask failed");
  }
  dds::GuardCondition stop(participant);
  dds::WaitSet waitset(participant);
  if (taker_kind == Taker::kWaitset) waitset.attach(*reader, 1);
  waitset.attach(stop, 2);
  std::thread taker([&] {
    for (;;) {
      auto triggered = waitset.wait(milliseconds(200));
      if (!triggered) continue;
      for (auto t : *triggered) {
        if (t == 2) return;
      }
      if (taker_kind == Taker::kWaitset) take();
    }
  });
  auto args = client_args("oneway", domain, {"A"}, nodes, seconds);
  args.push_back("--command-interval-us");
  args.push_back(std::to_string(interval_us));
  ClientOutput out;
  const auto finish = [&] {
    (void)stop.trigger();
    taker.join();
    (void)dds::DataListener::detach(*reader);  // every call over before taken_at is read
  };
  try {
    out = read_client(spawn_child(args, true, cpus.peer), seconds, on_ready, [] {});
  } catch (...) {
    finish();
    throw;
  }
  finish();
  std::vector<double> us;
  for (const auto& c : out.commands) {
    auto it = taken_at.find({c.mac, c.value});
    if (it != taken_at.end()) us.push_back(static_cast<double>(it->second - c.at) / 1e3);
  }
  return us;
}

std::string verdict(bool met) { return met ? "met" : "NOT met"; }

// Cyclone DDS alone on the state path: PumpStates written by this process
// with the bridge's participant and QoS (the bridge's default partition,
// state_writer_qos), each with a new analog input value, and taken by the
// subscriber process as in (1). Every `period`, every instance (ports x
// nodes) once, in `batches` batches `spacing` apart, from a thread of its
// own, from the client's "ready" until its window ends.
struct StatePattern {
  std::vector<std::string> ports;
  unsigned nodes = 0;
  Duration period{};
  unsigned batches = 1;
  Duration spacing{};
  // Cyclone's write batching (dds_write_set_batch, process-wide): a batch's
  // samples go out together at its end (dds_write_flush), not one datagram
  // per write.
  bool batched = false;
};

struct DirectStateResult {
  std::vector<double> latency_us;  // wall clock at take - source timestamp, as (1)
  std::uint64_t written = 0;       // within the window
  std::uint64_t taken = 0;
  double window_s = 0;
  double process_cpu_s = 0;  // this process over the window (Cyclone's threads included)
  double write_cpu_s = 0;    // the writing thread, inside its batches of writes
};

template <class OnReady, class OnEnd>
DirectStateResult direct_state(int domain, Placement cpus, double window_seconds,
                               const StatePattern& p, OnReady on_ready, OnEnd on_end) {
  dds::Participant participant(static_cast<dds_domainid_t>(domain), kRack);
  dds::Topic<dnbridge_PumpState> topic(participant);
  dds::Writer<dnbridge_PumpState> writer(participant, topic, dds::state_writer_qos(seconds(2)));
  struct Batching {
    explicit Batching(bool enable) : on(enable) {
      if (on) dds_write_set_batch(true);
    }
    ~Batching() {
      if (on) dds_write_set_batch(false);
    }
    bool on;
  } batching(p.batched);
  std::vector<dds::Owned<dnbridge_PumpState>> states(p.ports.size() * p.nodes);
  for (std::size_t i = 0; i < states.size(); ++i) {
    auto& st = states[i];
    dds::set_string(st->rack, kRack);
    dds::set_string(st->port, p.ports[i / p.nodes]);
    st->mac = static_cast<std::uint8_t>(1 + i % p.nodes);
    dds::set_string(st->name, fmt::format("pump-{}-{}", p.ports[i / p.nodes], st->mac));
    dds::set_string(st->idle_reason, "");
    st->online = st->inputs_valid = true;
    st->analog_input_count = 1;
    if (!writer.write(*st)) throw std::runtime_error("writing a PumpState failed");
  }
  DirectStateResult r;
  std::atomic<bool> stop{false};
  std::atomic<std::int64_t> write_cpu_ns{0};
  std::atomic<std::uint64_t> written{0};
  std::thread pace;
  std::int64_t cpu0 = 0, wall0 = 0;
  const auto per_batch = (states.size() + p.batches - 1) / p.batches;
  const auto ns = [](Duration d) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count();
  };
  auto start = [&] {
    wall0 = monotonic_ns();
    cpu0 = process_cpu_ns();
    pace = std::thread([&] {
      std::int64_t cycle = monotonic_ns();
      while (!stop.load(std::memory_order_relaxed)) {
        for (unsigned b = 0; b < p.batches; ++b) {
          sleep_until_monotonic(cycle + b * ns(p.spacing));
          const auto t0 = clock_ns(CLOCK_THREAD_CPUTIME_ID);
          const auto first = b * per_batch;
          for (auto i = first; i < std::min(first + per_batch, states.size()); ++i) {
            auto& st = *states[i];
            st.analog_input_raw[0] =
                static_cast<std::uint16_t>((st.analog_input_raw[0] + 1) % 4096);
            (void)writer.write(st);
            written.fetch_add(1, std::memory_order_relaxed);
          }
          if (p.batched) (void)dds_write_flush(writer.handle());
          write_cpu_ns.fetch_add(clock_ns(CLOCK_THREAD_CPUTIME_ID) - t0, std::memory_order_relaxed);
        }
        cycle += ns(p.period);
      }
    });
    on_ready();
  };
  auto end = [&] {
    r.window_s = static_cast<double>(monotonic_ns() - wall0) / 1e9;
    r.process_cpu_s = static_cast<double>(process_cpu_ns() - cpu0) / 1e9;
    r.write_cpu_s = static_cast<double>(write_cpu_ns.load()) / 1e9;
    r.written = written.load();
    stop = true;
    on_end();
  };
  auto args = client_args("state", domain, p.ports, p.nodes, window_seconds);
  ClientOutput out;
  try {
    out = read_client(spawn_child(args, true, cpus.peer), window_seconds, start, end);
  } catch (...) {
    stop = true;
    if (pace.joinable()) pace.join();
    throw;
  }
  stop = true;
  if (pace.joinable()) pace.join();
  r.latency_us = std::move(out.state_us);
  r.taken = out.taken;
  return r;
}

// (0d): one thread waking another of the same process, on the CPU it runs
// on, with nothing else to do: the one hand-over each of the bridge's paths
// makes (a received frame to the port's thread, a command from Cyclone's
// thread to it), as the simulated bus makes it: a time stamped, a queue
// under a mutex, a condition variable. One every 250 us, `seconds` long.
// The best case: the waking thread sleeps right after, so the woken one has
// the CPU at once; in the bridge the waking thread goes on with its work.
std::vector<double> thread_handover(double seconds) {
  std::mutex mutex;
  std::condition_variable woken;
  std::vector<std::int64_t> queue;
  bool stop = false;
  std::vector<double> latencies;
  latencies.reserve(static_cast<std::size_t>(seconds * 4000) + 16);
  std::thread waiter([&] {
    std::vector<std::int64_t> taken;
    std::unique_lock lock(mutex);
    for (;;) {
      woken.wait(lock, [&] { return stop || !queue.empty(); });
      if (stop) return;
      taken.swap(queue);
      lock.unlock();
      const auto now = steady_ns();
      for (auto at : taken) latencies.push_back(static_cast<double>(now - at) / 1e3);
      taken.clear();
      lock.lock();
    }
  });
  const auto start = monotonic_ns();
  const auto end = start + static_cast<std::int64_t>(seconds * 1e9);
  for (auto next = start; next < end; next += 250'000) {
    sleep_until_monotonic(next);
    {
      std::lock_guard lock(mutex);
      queue.push_back(steady_ns());
    }
    woken.notify_one();
  }
  {
    std::lock_guard lock(mutex);
    stop = true;
  }
  woken.notify_one();
  waiter.join();
  return latencies;
}

int run_bench(const Options& o) {
  const int domain = o.domain >= 0 ? o.domain : 200 + static_cast<int>(getpid() % 30);
  const std::string tag = fmt::format("dnbridge-bench-{}", getpid());
  setenv("CYCLONEDDS_URI", dds::loopback_config(tag).c_str(), 1);
  daemon::StderrLogSink log(LogLevel::kWarn);

  print_run_header("dnbridge benchmark", domain, tag);

  const int awake = o.hold_awake ? hold_cpus_awake() : -1;
  if (awake >= 0) {
    fmt::print("CPU idle: /dev/cpu_dma_latency held at 0 us for the whole run (no CPU halts)\n");
  } else {
    fmt::print("CPU idle: {}\n", o.hold_awake
                                     ? "/dev/cpu_dma_latency could not be held (not root?): "
                                       "CPUs halt when idle"
                                     : "CPUs halt when idle (--allow-idle)");
  }

  // The measured process on one CPU, its peer on another, for the bridge as
  // for ddsperf: a hand-over between threads of one process then stays on
  // its CPU (on a virtual machine waking another, idle, CPU can cost tens of
  // microseconds), and each pair is measured in the same layout.
  const Placement cpus =
      place_processes(o.pin, o.bridge_cpu, o.peer_cpu, "the bridge (this process, every thread)",
                      "the subscriber/commander process");

  if (!steady_clock_is_monotonic()) {
    fmt::print(stderr,
               "std::chrono::steady_clock is not CLOCK_MONOTONIC here: (2) cannot be measured\n");
    return 1;
  }
  fmt::print(
      "clock check: std::chrono::steady_clock reads CLOCK_MONOTONIC (1000 readings bracketed)\n\n");

  // (0), (1), (2) -------------------------------------------------------------
  // Each measurement has ddsperf running beside it: Cyclone's own latency and
  // the bridge's are taken over the same seconds, on the same CPUs.
  // ddsperf for as long as the measurement beside it.
  auto start_ddsperf = [&](std::optional<Ddsperf>& d, double seconds) {
    d.emplace(domain, seconds, o.ddsperf_rate, o.ddsperf_size, cpus);
  };
  struct Reference {
    double p50 = 0, p99 = 0;  // one-way, us
  };
  auto report_ddsperf = [&](std::optional<Ddsperf>& d) {
    if (!d) throw std::runtime_error("the measurement ended before it started");
    const DdsperfResult cyc = d->finish();
    d.reset();
    double window_p99_lo = cyc.windows.front().p99, window_p99_hi = window_p99_lo;
    for (const auto& w : cyc.windows) {
      window_p99_lo = std::min(window_p99_lo, w.p99);
      window_p99_hi = std::max(window_p99_hi, w.p99);
    }
    fmt::print("(0) Cyclone DDS, beside it: ddsperf {}(and ddsperf pong waitset)\n", cyc.command);
    fmt::print(
        "    one-way = round trip / 2 (as ddsperf prints it), {:.0f} round trips in {} one-second\n"
        "    windows (the first left out):  p50 {}  p99 {}  max {}\n"
        "    (p99 of single windows {:.1f}..{:.1f} us)\n",
        cyc.samples, cyc.windows.size(), us(cyc.half_rtt_p50), us(cyc.half_rtt_p99),
        us(cyc.half_rtt_max), window_p99_lo, window_p99_hi);
    return Reference{cyc.half_rtt_p50, cyc.half_rtt_p99};
  };

  if (o.latency_seconds > 0 && o.direct_seconds > 0) {
    const Summary h = summarize(thread_handover(std::min(o.direct_seconds, 5.0)));
    fmt::print(
        "(0d) a thread woken by another of this process {}, nothing else running\n"
        "     (a condition variable, one every 250 us; the waking thread then sleeps): the\n"
        "     hand-over each of the bridge's paths makes once, at its best\n"
        "     samples {}  p50 {}  p99 {}  max {}\n\n",
        cpus.tested >= 0 ? "on the same CPU" : "(both where the kernel puts them)", h.count,
        us(h.p50), us(h.p99), us(h.max));
  }

  // (0b), the listener's: what the bridge's command path adds is measured
  // against it.
  std::optional<Summary> direct_listener;
  if (o.latency_seconds > 0 && o.direct_seconds > 0) {
    for (const Taker taker : {Taker::kWaitset, Taker::kListener}) {
      const bool listener = taker == Taker::kListener;
      fmt::print(
          "(0b) Cyclone DDS alone on the path of a command: PumpCommands written as in (2) by the\n"
          "     commander process, taken in this process {},\n"
          "     with nothing behind it; one way, measured ({} s) ...\n",
          listener ? "by a listener on Cyclone's thread (as the bridge takes them)"
                   : "by a reader on a waitset thread of its own",
          o.direct_seconds);
      std::fflush(stdout);
      std::optional<Ddsperf> ddsperf;
      const Summary d = summarize(
          direct_oneway(domain, cpus, o.direct_seconds, o.command_interval_ms * 1000,
                        o.latency_nodes, taker, [&] { start_ddsperf(ddsperf, o.direct_seconds); }));
      const Reference ref = report_ddsperf(ddsperf);
      fmt::print("(0b) write -> take ({}), one way: samples {}  p50 {}  p99 {}  max {}\n",
                 listener ? "listener" : "waitset", d.count, us(d.p50), us(d.p99), us(d.max));
      fmt::print("     ratio to ddsperf's one-way:  p50 {:.2f}  p99 {:.2f}\n\n", d.p50 / ref.p50,
                 d.p99 / ref.p99);
      if (listener) direct_listener = d;
    }
  }

  for (const int poll_ms : o.latency_poll_ms) {
    if (o.latency_seconds <= 0) break;
    // (0c): Cyclone alone on the state path, in the pattern of this run's
    // poll responses (each node once per poll period, one response frame
    // time, about 250 us at 500 kbit/s, apart).
    std::optional<Summary> direct_state_summary;
    if (o.direct_seconds > 0) {
      fmt::print(
          "(0c) Cyclone DDS alone on the state path: PumpStates written in this process with "
          "the\n     bridge's QoS, {} instances every {} ms 250 us apart, each a new analog "
          "value, taken by\n     the subscriber process as in (1); wall clock at take - source "
          "timestamp ({} s) ...\n",
          o.latency_nodes, poll_ms, o.direct_seconds);
      std::fflush(stdout);
      std::optional<Ddsperf> ddsperf;
      const StatePattern pattern{
          {"A"}, o.latency_nodes, milliseconds(poll_ms), o.latency_nodes, microseconds(250)};
      const auto r = direct_state(
          domain, cpus, o.direct_seconds, pattern,
          [&] { start_ddsperf(ddsperf, o.direct_seconds); }, [] {});
      const Reference ref = report_ddsperf(ddsperf);
      const Summary d = summarize(r.latency_us);
      fmt::print("(0c) write -> take, one way: samples {}  p50 {}  p99 {}  max {}\n", d.count,
                 us(d.p50), us(d.p99), us(d.max));
      fmt::print("     ratio to ddsperf's one-way:  p50 {:.2f}  p99 {:.2f}\n\n", d.p50 / ref.p50,
                 d.p99 / ref.p99);
      if (d.count > 0) direct_state_summary = d;
    }

    BridgeSetup s;
    s.ports = {"A"};
    s.nodes = o.latency_nodes;
    s.bitrate = can::kBitrate500k;
    s.poll_period = milliseconds(poll_ms);
    s.publish = {seconds(1), 0.0};
    s.ramp = true;
    s.record_outputs = true;
    fmt::print(
        "(1)(2) bridge: 1 port, {} CDN127s at 500 kbit/s, polled every {} ms{}; every poll "
        "response\n       carries a new analog input (deadband 0: each one is published); a "
        "PumpCommand\n       every {} ms on average, round robin, each a new analog output; {} "
        "s ...\n",
        s.nodes, poll_ms, poll_ms == 100 ? " (as shipped)" : "", o.command_interval_ms,
        o.latency_seconds);
    std::fflush(stdout);
    Bridge bridge(s, domain, log);
    const auto offset_before = realtime_ns() - monotonic_ns();
    bridge.start();
    auto args = client_args("latency", domain, s.ports, s.nodes, o.latency_seconds);
    args.push_back("--command-interval-us");
    args.push_back(std::to_string(o.command_interval_ms * 1000));
    std::optional<Ddsperf> ddsperf;
    ClientOutput out = read_client(
        spawn_child(args, true, cpus.peer), o.latency_seconds,
        [&] { start_ddsperf(ddsperf, o.latency_seconds); }, [] {});
    bridge.stop();
    const auto offset_after = realtime_ns() - monotonic_ns();
    const auto drift_us = static_cast<double>(offset_after - offset_before) / 1e3;
    const Reference cyc = report_ddsperf(ddsperf);

    const Summary state = summarize(out.state_us);
    fmt::print("(1) poll response received by the master -> PumpState taken by the subscriber\n");
    fmt::print("    samples {}  p50 {}  p99 {}  max {}  min {}\n", state.count, us(state.p50),
               us(state.p99), us(state.max), us(state.min));
    fmt::print(
        "    wall clock moved {:+.1f} us against CLOCK_MONOTONIC during the run (an error of "
        "at most that)\n",
        drift_us);
    fmt::print("    ratio to Cyclone one-way:  p50 {:.2f}  p99 {:.2f}   target p99 <= 1.5: {}\n",
               state.p50 / cyc.p50, state.p99 / cyc.p99, verdict(state.p99 <= 1.5 * cyc.p99));
    if (direct_state_summary) {
      const double added = state.p99 - direct_state_summary->p99;
      fmt::print(
          "    the bridge's own addition: p99 {} - (0c)'s p99 {} = {}   target <= 10 us: {}\n"
          "                               p50 {} - (0c)'s p50 {} = {}\n",
          us(state.p99), us(direct_state_summary->p99), us(added), verdict(added <= 10.0),
          us(state.p50), us(direct_state_summary->p50), us(state.p50 - direct_state_summary->p50));
    }
    // (1) in two, sample by sample: the response's way to the port's thread
    // (the CAN controller waking it: here the simulated bus's thread, for a
    // SocketCAN socket the kernel), and from there to the take (the bridge's
    // own work, then Cyclone's, as in (0c), whose writer is awake when it stamps).
    // Only responses that found the port's thread waiting, and were the
    // first frame it was handed: for the others the time to the thread
    // includes its own work. (A value a node's input took twice, its ramp
    // having wrapped, matches no sample.)
    constexpr std::int64_t kNotMatched = -1;
    std::map<std::pair<std::size_t, unsigned>, std::int64_t> wake_ns;
    for (const auto& h : bridge.handed_responses()) {
      const auto [it, added] = wake_ns.try_emplace({h.key, h.value}, h.slept ? h.ns : kNotMatched);
      if (!added) it->second = kNotMatched;
    }
    std::vector<double> wake_us, after_wake_us;
    for (const auto& st : out.states) {
      const auto it = wake_ns.find({st.key, st.value});
      if (it == wake_ns.end() || it->second == kNotMatched) continue;
      wake_us.push_back(static_cast<double>(it->second) / 1e3);
      after_wake_us.push_back(st.us - wake_us.back());
    }
    const Summary wake = summarize(wake_us);
    const Summary after_wake = summarize(after_wake_us);
    fmt::print(
        "    in two ({} of the {} samples: those whose response woke the port's thread):\n"
        "      the response handed to the port's thread (its wake-up):  p50 {}  p99 {}  max {}\n"
        "      the port's thread having it -> PumpState taken:          p50 {}  p99 {}  max {}\n",
        after_wake.count, state.count, us(wake.p50), us(wake.p99), us(wake.max), us(after_wake.p50),
        us(after_wake.p99), us(after_wake.max));
    if (direct_state_summary) {
      fmt::print("    the bridge's own addition after the wake-up, against (0c): p50 {}  p99 {}\n",
                 us(after_wake.p50 - direct_state_summary->p50),
                 us(after_wake.p99 - direct_state_summary->p99));
    }

    std::map<std::pair<unsigned, unsigned>, PortWire::OutputFrame> frames;
    for (const auto& f : bridge.output_frames()) frames.emplace(std::make_pair(f.mac, f.value), f);
    std::map<std::pair<unsigned, unsigned>, PortWire::WrittenFrame> written;
    for (const auto& f : bridge.written_frames())
      written.emplace(std::make_pair(f.mac, f.value), f);
    std::vector<double> to_write, to_start, to_end, to_write_free;
    // Commands that met a poll in flight: from that poll's response received
    // to the next poll frame written, and that frame's time on the wire.
    std::vector<double> after_response_us;
    std::vector<double> to_woken, woken_to_write;
    // Of those, the ones whose thread a wake() after the command woke: until
    // that wake() (Cyclone's delivery, the bridge's listener), and from it
    // to the thread running (the hand-over alone).
    std::vector<double> to_wake_call, wake_to_woken;
    std::size_t not_split = 0;
    double frame_us = 0;
    std::size_t waited = 0;
    for (const auto& c : out.commands) {
      auto it = frames.find({c.mac, c.value});
      auto wr = written.find({c.mac, c.value});
      if (it == frames.end() || wr == written.end()) continue;
      const double write_us = static_cast<double>(wr->second.at - c.at) / 1e3;
      to_write.push_back(write_us);
      frame_us = std::max(frame_us, static_cast<double>(it->second.end - it->second.start) / 1e3);
      if (wr->second.after_response) {
        ++waited;
        after_response_us.push_back(static_cast<double>(wr->second.at - wr->second.response_rx) /
                                    1e3);
      } else {
        to_write_free.push_back(write_us);
        // In two: until the port's thread woke for it, and its own work
        // from there. Only when the thread was waiting when the command was
        // written and woke after: it may still have woken for something
        // else (a poll due, a response) before the command reached it.
        if (wr->second.waited_since <= c.at && wr->second.woke >= c.at) {
          to_woken.push_back(static_cast<double>(wr->second.woke - c.at) / 1e3);
          woken_to_write.push_back(static_cast<double>(wr->second.at - wr->second.woke) / 1e3);
          if (wr->second.woken_by >= c.at) {
            to_wake_call.push_back(static_cast<double>(wr->second.woken_by - c.at) / 1e3);
            wake_to_woken.push_back(static_cast<double>(wr->second.woke - wr->second.woken_by) /
                                    1e3);
          }
        } else {
          ++not_split;
        }
      }
      to_start.push_back(static_cast<double>(it->second.start - c.at) / 1e3);
      to_end.push_back(static_cast<double>(it->second.end - c.at) / 1e3);
    }
    const Summary cmd_write = summarize(to_write);
    const Summary cmd_write_free = summarize(to_write_free);
    const Summary cmd = summarize(to_start);
    const Summary cmd_end = summarize(to_end);
    fmt::print("(2) PumpCommand written -> poll frame with the new outputs\n");
    fmt::print("    commands written {}, their poll frames found {}\n", out.commands.size(),
               cmd.count);
    fmt::print("    to the frame written to the CAN interface:  p50 {}  p99 {}  max {}  min {}\n",
               us(cmd_write.p50), us(cmd_write.p99), us(cmd_write.max), us(cmd_write.min));
    fmt::print(
        "    {} of them ({:.1f} %) came while the node's previous poll was unanswered and\n"
        "    went out with its response (one poll at a time on a poll connection); the "
        "others:\n"
        "                                                p50 {}  p99 {}  max {}\n",
        waited, 100.0 * static_cast<double>(waited) / static_cast<double>(to_write.size()),
        us(cmd_write_free.p50), us(cmd_write_free.p99), us(cmd_write_free.max));
    if (!after_response_us.empty()) {
      // Such a command waits for the remaining transaction of the poll in
      // flight, then for the master to write the next poll: that last part
      // is to take no longer than one frame time.
      const Summary after = summarize(after_response_us);
      fmt::print(
          "    those {}: from the response of the poll in flight received to the new poll "
          "written\n"
          "                                                p50 {}  p99 {}  max {}\n"
          "      target p99 <= one frame time ({}, the poll frame at 500 kbit/s): {}\n",
          waited, us(after.p50), us(after.p99), us(after.max), us(frame_us),
          verdict(after.p99 <= frame_us));
    }
    fmt::print(
        "    to its start of frame on the bus:           p50 {}  p99 {}  max {}  min {}\n"
        "      (adds waiting for a frame already on the 500 kbit/s wire, and arbitration)\n",
        us(cmd.p50), us(cmd.p99), us(cmd.max), us(cmd.min));
    fmt::print("    to its end of frame:                        p50 {}  p99 {}\n", us(cmd_end.p50),
               us(cmd_end.p99));
    fmt::print(
        "    ratio to Cyclone one-way, written:          p50 {:.2f}  p99 {:.2f}   target p99 "
        "<= 1.5: {}\n",
        cmd_write.p50 / cyc.p50, cmd_write.p99 / cyc.p99, verdict(cmd_write.p99 <= 1.5 * cyc.p99));
    fmt::print(
        "    ratio to Cyclone one-way, written, no poll in flight:  p50 {:.2f}  p99 {:.2f}\n",
        cmd_write_free.p50 / cyc.p50, cmd_write_free.p99 / cyc.p99);
    if (direct_listener) {
      const double added = cmd_write_free.p99 - direct_listener->p99;
      fmt::print(
          "    the bridge's own addition, no poll in flight: p99 {} - (0b) listener's p99 {} = {}"
          "   target <= 10 us: {}\n",
          us(cmd_write_free.p99), us(direct_listener->p99), us(added), verdict(added <= 10.0));
      fmt::print(
          "                                                 p50 {} - (0b) listener's p50 {} = {}\n",
          us(cmd_write_free.p50), us(direct_listener->p50),
          us(cmd_write_free.p50 - direct_listener->p50));
    }
    {
      const Summary woken = summarize(to_woken);
      const Summary work = summarize(woken_to_write);
      fmt::print(
          "    no poll in flight, in two ({} commands written while the port's thread waited; {} "
          "others):\n"
          "      command written -> the port's thread woken for it:  p50 {}  p99 {}  max {}\n"
          "      the port's thread woken -> the frame written:       p50 {}  p99 {}  max {}\n",
          woken.count, not_split, us(woken.p50), us(woken.p99), us(woken.max), us(work.p50),
          us(work.p99), us(work.max));
      if (direct_listener) {
        fmt::print(
            "      the first against (0b) listener (Cyclone's delivery): p50 {}  p99 {} (the "
            "bridge's\n      listener taking the command to the port's inbox, and the "
            "hand-over to the port's thread)\n",
            us(woken.p50 - direct_listener->p50), us(woken.p99 - direct_listener->p99));
      }
      const Summary to_call = summarize(to_wake_call);
      const Summary handing = summarize(wake_to_woken);
      fmt::print(
          "      the first in two ({} of them: the thread woken by a wake() after the command):\n"
          "        command written -> the listener wakes the port's loop: p50 {}  p99 {}  max {}\n"
          "        that wake -> the port's thread running (the hand-over): p50 {}  p99 {}  max "
          "{}\n",
          to_call.count, us(to_call.p50), us(to_call.p99), us(to_call.max), us(handing.p50),
          us(handing.p99), us(handing.max));
      if (direct_listener) {
        fmt::print(
            "        the listener's part against (0b) listener: p50 {}  p99 {} (the bridge's "
            "listener\n        taking the command to the port's inbox)\n",
            us(to_call.p50 - direct_listener->p50), us(to_call.p99 - direct_listener->p99));
      }
    }
    fmt::print(
        "    ratio to Cyclone one-way, start of frame:   p50 {:.2f}  p99 {:.2f}   target p99 "
        "<= 1.5: {}\n\n",
        cmd.p50 / cyc.p50, cmd.p99 / cyc.p99, verdict(cmd.p99 <= 1.5 * cyc.p99));
    std::fflush(stdout);
    if (state.count == 0 || cmd.count == 0) throw std::runtime_error("no latency was measured");
  }

  // (3) ---------------------------------------------------------------------
  struct CpuFigures {
    double bridge_pct;     // of one core
    double samples_per_s;  // PumpState taken by the subscriber
  };
  auto cpu_run = [&](const char* title, double window, bool every_poll) {
    BridgeSetup s;
    s.ports = {"P1", "P2", "P3", "P4"};
    s.nodes = 63;
    s.bitrate = 0;  // ideal bus: see the bus load printed below
    s.publish = every_poll ? rack::PublishPolicy{seconds(1), 0.0} : rack::PublishPolicy{};
    s.ramp = every_poll;
    fmt::print("{}\n", title);
    std::fflush(stdout);
    Bridge bridge(s, domain, log);
    bridge.start();
    std::int64_t wall0 = 0, cpu0 = 0, sim0 = 0;
    std::uint64_t polls0 = 0, responses0 = 0, bits0 = 0;
    const auto online_from = monotonic_ns();
    double online_s = 0;
    auto args = client_args("count", domain, s.ports, s.nodes, window);
    args.push_back("--command-once");
    const std::set<pid_t> port_tids = bridge.port_threads();
    const std::set<pid_t> sim_tids = bridge.sim_threads();
    std::map<pid_t, ThreadSample> threads0, threads1;
    auto start = [&] {
      online_s = static_cast<double>(monotonic_ns() - online_from) / 1e9;
      wall0 = monotonic_ns();
      cpu0 = process_cpu_ns();
      sim0 = bridge.sim_cpu_ns();
      polls0 = bridge.polls();
      responses0 = bridge.responses();
      bits0 = bridge.bus_bits();
      threads0 = snapshot_threads();
    };
    double wall = 0, cpu = 0, sim_cpu = 0, polls = 0, responses = 0, bits = 0;
    auto end = [&] {
      // The client has taken samples for `window` seconds since it said
      // ready, and is still subscribed and commanding.
      wall = static_cast<double>(monotonic_ns() - wall0) / 1e9;
      cpu = static_cast<double>(process_cpu_ns() - cpu0) / 1e9;
      sim_cpu = static_cast<double>(bridge.sim_cpu_ns() - sim0) / 1e9;
      polls = static_cast<double>(bridge.polls() - polls0);
      responses = static_cast<double>(bridge.responses() - responses0);
      bits = static_cast<double>(bridge.bus_bits() - bits0);
      threads1 = snapshot_threads();
    };
    ClientOutput out = read_client(spawn_child(args, true, cpus.peer), window, start, end);
    bridge.stop();
    if (wall <= 0) throw std::runtime_error("the CPU window was not measured");
    const double bridge_pct = 100.0 * (cpu - sim_cpu) / wall;
    fmt::print("    all {} nodes online after {:.1f} s; measured over {:.1f} s of wall time\n",
               s.ports.size() * s.nodes, online_s, wall);
    fmt::print(
        "    polls {:.0f}/s (expected {:.0f}/s), poll responses {:.0f}/s, PumpState samples "
        "taken by the subscriber {:.0f}/s\n",
        polls / wall, static_cast<double>(s.ports.size() * s.nodes) * 100.0, responses / wall,
        static_cast<double>(out.taken) / out.window_s);
    fmt::print(
        "    bus: {:.0f} bit/s per port, {:.0f} % of a 500 kbit/s bus: hence the ideal bus\n",
        bits / wall / 4, 100.0 * bits / wall / 4 / 500000.0);
    fmt::print(
        "    CPU: process {:.1f} %, simulated devices' threads {:.1f} %, bridge {:.1f} % of "
        "one core\n",
        100.0 * cpu / wall, 100.0 * sim_cpu / wall, bridge_pct);
    struct Group {
      const char* name;
      double cpu_s = 0;
      double switches = 0;
      unsigned threads = 0;
    };
    // The bridge's threads by their names (adapters/daemon: the reply
    // outbox, the DDS input; the port loops write the state samples);
    // Cyclone's by elimination.
    std::array<Group, 6> groups{{{"port loops"},
                                 {"reply outbox"},
                                 {"DDS input"},
                                 {"main and other"},
                                 {"Cyclone DDS's own"},
                                 {"simulated devices"}}};
    const auto group_of = [&](pid_t tid, const std::string& name) -> Group& {
      if (port_tids.count(tid)) return groups[0];
      if (sim_tids.count(tid)) return groups[5];
      if (name == "dds reply out") return groups[1];
      if (name == "dds input") return groups[2];
      if (name.rfind("dnbridge-ben", 0) == 0 || name == "reload" || name == "sd_notify") {
        return groups[3];
      }
      return groups[4];
    };
    for (const auto& [tid, t1] : threads1) {
      auto it = threads0.find(tid);
      if (it == threads0.end()) continue;
      Group& g = group_of(tid, t1.name);
      g.cpu_s += t1.cpu_s - it->second.cpu_s;
      g.switches += static_cast<double>(t1.switches - it->second.switches);
      ++g.threads;
    }
    fmt::print("    by thread (/proc, 10 ms ticks):");
    for (const auto& g : groups) {
      fmt::print(" {} ({}) {:.1f} %, {:.0f} switches/s;", g.name, g.threads, 100.0 * g.cpu_s / wall,
                 g.switches / wall);
    }
    fmt::print("\n");
    return CpuFigures{bridge_pct, static_cast<double>(out.taken) / out.window_s};
  };

  const CpuFigures shipped = cpu_run(
      "(3) CPU: 4 ports x 63 CDN127s, each polled every 10 ms, on an ideal bus (no bit timing);\n"
      "    publish policy as shipped (on change, 0.05 V deadband, at least once a second); a\n"
      "    subscriber in another process takes every PumpState; one PumpCommand per pump at the "
      "start ...",
      o.cpu_seconds, false);
  fmt::print("    target < 10 % of one core: {}\n\n", verdict(shipped.bridge_pct < 10.0));
  if (o.busy_seconds > 0) {
    const CpuFigures busy = cpu_run(
        "(3b) the same, but every poll response a new analog input and deadband 0: a PumpState "
        "per poll ...",
        o.busy_seconds, true);
    fmt::print("\n");
    // (3c): what Cyclone's writes of (3b)'s samples cost, alone.
    fmt::print(
        "(3c) Cyclone DDS alone writing (3b)'s samples: PumpStates of 4 x 63 instances, each "
        "every\n     10 ms, in batches every 1 ms, written in this process with the bridge's "
        "QoS, taken by\n     the subscriber process ...\n");
    std::fflush(stdout);
    StatePattern pattern{{"P1", "P2", "P3", "P4"}, 63, milliseconds(10), 10, milliseconds(1)};
    // CPU per sample written: in the write calls, and of the process.
    const auto write_cost = [&](const StatePattern& p) {
      const auto r = direct_state(
          domain, cpus, o.busy_seconds, p, [] {}, [] {});
      if (r.written == 0 || r.window_s <= 0) throw std::runtime_error("(3c) wrote nothing");
      const double n = static_cast<double>(r.written);
      const double write_us = r.write_cpu_s / n * 1e6;
      const double process_us = r.process_cpu_s / n * 1e6;
      fmt::print(
          "    written {:.0f}/s, taken {:.0f}/s; CPU per sample: {:.2f} us in the write calls{}, "
          "{:.2f} us\n     for this process in all (Cyclone's own threads included; {:.1f} % of "
          "one core)\n",
          n / r.window_s, static_cast<double>(r.taken) / r.window_s, write_us,
          p.batched ? " and flushes" : "", process_us, 100.0 * r.process_cpu_s / r.window_s);
      return process_us;
    };
    const double process_us = write_cost(pattern);
    // (3b) against (3): the CPU each further published sample costs the
    // bridge, and Cyclone's share of it.
    const double extra = busy.samples_per_s - shipped.samples_per_s;
    if (extra > 0) {
      const double per_sample_us = (busy.bridge_pct - shipped.bridge_pct) / 100.0 / extra * 1e6;
      fmt::print(
          "    (3b) - (3): {:.2f} us of the bridge's CPU per further PumpState published; of "
          "it Cyclone's\n     write {:.2f} us (3c), the bridge's own work {:.2f} us\n",
          per_sample_us, process_us, per_sample_us - process_us);
    }
    fmt::print(
        "(3d) the same as (3c) with Cyclone's write batching (dds_write_set_batch; a flush after "
        "each\n     batch: its samples leave together) ...\n");
    std::fflush(stdout);
    pattern.batched = true;
    (void)write_cost(pattern);
    fmt::print("\n");
  }
  fmt::print("load average at end: {}\n", load_average());
  return 0;
}

}  // namespace
}  // namespace dnbridge::bench

int main(int argc, char** argv) {
  using namespace dnbridge::bench;
  CLI::App app{"dnbridge-bench: the bridge's latency and CPU time beside Cyclone DDS's own"};
  Options o;
  ClientOptions client;
  std::string ports;
  app.add_option("--ddsperf-rate", o.ddsperf_rate, "ddsperf pings per second")
      ->capture_default_str();
  app.add_option("--latency-seconds", o.latency_seconds, "(1) and (2), each run; 0 to skip")
      ->capture_default_str();
  app.add_option("--direct-seconds", o.direct_seconds, "(0b) and (0c), each run; 0 to skip")
      ->capture_default_str();
  app.add_option("--latency-poll-ms", o.latency_poll_ms, "a run of (1) and (2) per poll period")
      ->capture_default_str();
  app.add_option("--latency-nodes", o.latency_nodes, "nodes for (1) and (2)")
      ->capture_default_str();
  app.add_option("--command-interval-ms", o.command_interval_ms, "(2)")->capture_default_str();
  app.add_option("--cpu-seconds", o.cpu_seconds, "(3) measurement window")->capture_default_str();
  app.add_option("--busy-seconds", o.busy_seconds, "(3b), (3c) and (3d) windows, 0 to skip")
      ->capture_default_str();
  app.add_option("--domain", o.domain, "DDS domain (default: from the process id)");
  app.add_option("--bridge-cpu", o.bridge_cpu, "CPU of the bridge and of ddsperf pong")
      ->capture_default_str();
  app.add_option("--peer-cpu", o.peer_cpu, "CPU of the subscriber/commander and of ddsperf ping")
      ->capture_default_str();
  app.add_flag("!--no-pin", o.pin, "let the kernel place every process and thread");
  app.add_flag("!--allow-idle", o.hold_awake, "do not hold /dev/cpu_dma_latency at 0");
  // The client role (re-executed by the benchmark itself).
  app.add_option("--client", client.mode)->group("");
  app.add_option("--ports", ports)->group("");
  app.add_option("--nodes", client.nodes)->group("");
  app.add_option("--seconds", client.seconds)->group("");
  app.add_option("--command-interval-us", client.command_interval_us)->group("");
  app.add_flag("--command-once", client.command_once)->group("");
  CLI11_PARSE(app, argc, argv);

  try {
    if (!client.mode.empty()) {
      client.domain = o.domain;
      for (std::size_t at = 0; at <= ports.size();) {
        const auto comma = std::min(ports.find(',', at), ports.size());
        client.ports.push_back(ports.substr(at, comma - at));
        at = comma + 1;
      }
      return run_client(client);
    }
    return run_bench(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dnbridge-bench: %s\n", e.what());
    return 1;
  }
}
