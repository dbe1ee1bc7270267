// The bridge that (1), (2) and (3) measure, and the taps on its ports.
#include "bridge_bench_bridge.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <future>
#include <mutex>
#include <optional>
#include <utility>

#include "bridge/devicenet/wire/identifier.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"
#include "bridge_bench.hpp"

namespace dnbridge::bench {

using devicenet::MacId;

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

namespace {

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

pid_t this_thread_id() { return static_cast<pid_t>(gettid()); }

// The daemon's configuration: every port of `s`, each with nodes 1..s.nodes.
daemon::DaemonConfig bridge_config(const BridgeSetup& s, int domain) {
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
  return c;
}

// One record of every port's wire, in port order.
template <class Frame>
std::vector<Frame> gather(const std::vector<std::unique_ptr<PortWire>>& wires,
                          std::vector<Frame> PortWire::*record) {
  std::vector<Frame> all;
  for (const auto& w : wires) {
    std::lock_guard lock(w->mutex);
    const auto& frames = (*w).*record;
    all.insert(all.end(), frames.begin(), frames.end());
  }
  return all;
}

}  // namespace

Bridge::Bridge(const BridgeSetup& s, int domain, LogSink& log) {
  daemon::DaemonConfig c = bridge_config(s, domain);
  const auto format = profiles::cdn127::poll_format(
                          profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn127))
                          .value();
  auto factory = [this, &s, &log,
                  format](const daemon::PortConfig& p) -> std::unique_ptr<port::CanBackend> {
    return make_backend(s, p, format, log);
  };
  daemon_ = std::make_unique<daemon::Daemon>(std::move(c), log, factory);
}

Bridge::~Bridge() { stop(); }

std::unique_ptr<port::CanBackend> Bridge::make_backend(const BridgeSetup& s,
                                                       const daemon::PortConfig& p,
                                                       const profiles::cdn127::PollFormat& format,
                                                       LogSink& log) {
  std::vector<MacId> macs;
  for (const auto& n : p.nodes) macs.push_back(n.pump.node.mac);
  auto backend = std::make_unique<sim::ThreadedSimBackend>(p.bitrate, macs, &log);
  auto wire = std::make_unique<PortWire>();
  wire->backend = backend.get();
  wire->bitrate = p.bitrate;
  wire->ramp = s.ramp;
  wire->record_outputs = s.record_outputs;
  wire->index =
      static_cast<std::size_t>(std::find(s.ports.begin(), s.ports.end(), p.name) - s.ports.begin());
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
}

void Bridge::start() { daemon_->start(); }

void Bridge::stop() {
  if (daemon_) daemon_->stop();
}

std::int64_t Bridge::sim_cpu_ns() const {
  std::int64_t t = 0;
  for (auto* b : backends_) t += b->sim_thread_cpu_time().count();
  return t;
}

std::uint64_t Bridge::polls() const {
  std::uint64_t n = 0;
  for (const auto& w : wires_) n += w->polls.load();
  return n;
}

std::uint64_t Bridge::responses() const {
  std::uint64_t n = 0;
  for (const auto& w : wires_) n += w->responses.load();
  return n;
}

std::uint64_t Bridge::bus_bits() const {
  std::uint64_t n = 0;
  for (auto* b : backends_) n += b->counters().bits;
  return n;
}

std::set<pid_t> Bridge::port_threads() {
  std::set<pid_t> tids;
  for (const auto& p : daemon_->config().ports) {
    std::promise<pid_t> tid;
    daemon_->port(p.name)->post([&tid](port::CanBackend&) { tid.set_value(this_thread_id()); });
    tids.insert(tid.get_future().get());
  }
  return tids;
}

std::set<pid_t> Bridge::sim_threads() {
  std::set<pid_t> tids;
  for (auto* b : backends_) {
    std::promise<pid_t> tid;
    b->post([&tid] { tid.set_value(this_thread_id()); });
    tids.insert(tid.get_future().get());
  }
  return tids;
}

std::vector<OutputFrame> Bridge::output_frames() {
  return gather(wires_, &PortWire::output_frames);
}

std::vector<WrittenFrame> Bridge::written_frames() {
  return gather(wires_, &PortWire::written_frames);
}

std::vector<Bridge::Handed> Bridge::handed_responses() {
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

}  // namespace dnbridge::bench
