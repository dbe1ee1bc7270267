// dnbridge-dds-bench: what the product's type, QoS and way of taking cost
// Cyclone DDS itself, measured one change at a time, from ddsperf's own
// set-up to the product's command path and state path.
//
// Two processes, as a rack's bridge and a supervisor on one host: this one
// (the bridge's side, on --bridge-cpu) and this same program re-executed with
// --peer (the supervisor's side, on --peer-cpu). Each row of the table is a
// path: a type, the writer's and the reader's QoS, which side writes, how
// often, and how the reader takes (a waitset on a thread of its own, or a
// DATA_AVAILABLE listener on Cyclone's delivering thread). Its latency is one
// way: CLOCK_MONOTONIC just before the write in one process, just after the
// take in the other (one host, one clock). The round-trip row halves round
// trips as ddsperf does, and also shows each of their two legs one way.
//
// The paths are measured in slots of --seconds, one after the other, and the
// sequence --rounds times, so that a change in the machine over the run falls
// on every path alike; ddsperf itself (ping and pong, on the same CPUs) has a
// slot of its own in each round. Nothing else of the product runs: no bridge,
// no bus.
//
// It reports figures; it exits non-zero only when the run itself fails.
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/listener.hpp"
#include "adapters/dds/loopback.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"
#include "bench_process.hpp"
#include "ddsperf.hpp"
#include "figures.hpp"
#include "probe.h"

namespace dnbridge::dds {
template <>
struct TopicTraits<dnbridge_bench_Probe> {
  static constexpr const char* kName = "dnbridge_bench/Probe";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_bench_Probe_desc;
};
}  // namespace dnbridge::dds

namespace dnbridge::bench {
namespace {

constexpr const char* kRack = "bench";
// ddsperf's "size 128": the serialized Probe (4-byte sequence number, key,
// sequence length and 116 bytes) is as large.
constexpr std::size_t kBaggage = 116;
// Samples go round-robin over this many instances (keys), as commands and
// states go over a port's nodes.
constexpr std::uint32_t kInstances = 8;
// Between two slots: the last samples of one arrive before the next starts.
constexpr std::int64_t kSlotGapNs = 500'000'000;
// ddsperf's slot: its start-up and the first (warm-up) window it prints,
// which is left out, come on top of the measured seconds.
constexpr std::int64_t kDdsperfExtraNs = 8'000'000'000;

// ---------------------------------------------------------------------------
// The paths

enum class Type { kProbe, kCommand, kState };

// Qos of the reference rows: ddsperf's ping and pong (reliable, keep last 1,
// volatile, no other policy set).
dds::Qos ddsperf_qos() {
  dds::Qos q;
  q.reliable().keep_last(1);
  return q;
}

const std::vector<std::string>& partition() {
  static const std::vector<std::string> p = dds::rack_partitions(kRack);
  return p;
}

dds::Qos with_partition() {
  auto q = ddsperf_qos();
  q.partitions(partition());
  return q;
}

dds::Qos with_ownership(bool writer) {
  auto q = with_partition();
  q.exclusive_ownership();
  if (writer) q.ownership_strength(10);
  return q;
}

// The writer orders by source timestamp, the reader by reception (the
// product's command reader; see dds::command_reader_qos).
dds::Qos with_order(bool writer) {
  auto q = with_ownership(writer);
  q.destination_order_by_source_timestamp(writer);
  return q;
}

struct Path {
  std::string label;
  Type type = Type::kProbe;
  bool peer_writes = true;  // the supervisor's side writes (a command), else this side (a state)
  bool round_trip = false;  // this side writes each sample back on a second topic
  bool listener = false;    // the taking side takes in a listener, else on a waitset thread
  std::int64_t period_ns = 0;
  bool random_gaps = false;  // gaps drawn from 0.5..1.5 x the period, else a fixed period
  std::function<dds::Qos()> writer_qos, reader_qos;
  bool ddsperf = false;  // ddsperf's own processes, none of ours
  // The row differs from the row above it in one thing only: the table
  // prints what that change costs.
  bool chained = true;
};

std::vector<Path> make_paths(std::int64_t command_period_ns) {
  const auto c = command_period_ns;
  std::vector<Path> p;
  auto add = [&](Path path) { p.push_back(std::move(path)); };
  add({.label = "ddsperf ping/pong (500 Hz, size 128, waitset), round trip / 2",
       .period_ns = 2'000'000,
       .writer_qos = {},
       .reader_qos = {},
       .ddsperf = true,
       .chained = false});
  add({.label = "Probe, ddsperf's QoS, 500 Hz, round trip / 2 (as ddsperf)",
       .round_trip = true,
       .period_ns = 2'000'000,
       .writer_qos = ddsperf_qos,
       .reader_qos = ddsperf_qos,
       .chained = false});
  add({.label = "Probe, ddsperf's QoS, 500 Hz, one way",
       .period_ns = 2'000'000,
       .writer_qos = ddsperf_qos,
       .reader_qos = ddsperf_qos,
       .chained = false});
  add({.label = "  at the commands' rate",
       .period_ns = c,
       .random_gaps = true,
       .writer_qos = ddsperf_qos,
       .reader_qos = ddsperf_qos});
  add({.label = "  PumpCommand (keyed, strings) for Probe",
       .type = Type::kCommand,
       .period_ns = c,
       .random_gaps = true,
       .writer_qos = ddsperf_qos,
       .reader_qos = ddsperf_qos});
  add({.label = "  + the rack's partition",
       .type = Type::kCommand,
       .period_ns = c,
       .random_gaps = true,
       .writer_qos = with_partition,
       .reader_qos = with_partition});
  add({.label = "  + exclusive ownership (strength 10)",
       .type = Type::kCommand,
       .period_ns = c,
       .random_gaps = true,
       .writer_qos = [] { return with_ownership(true); },
       .reader_qos = [] { return with_ownership(false); }});
  add({.label = "  + destination order (writer by source time)",
       .type = Type::kCommand,
       .period_ns = c,
       .random_gaps = true,
       .writer_qos = [] { return with_order(true); },
       .reader_qos = [] { return with_order(false); }});
  add({.label = "  + automatic liveliness, 5 s lease: the product's command QoS",
       .type = Type::kCommand,
       .period_ns = c,
       .random_gaps = true,
       .writer_qos = [] { return dds::command_writer_qos(partition(), 10, seconds(5)); },
       .reader_qos = [] { return dds::command_reader_qos(partition()); }});
  add({.label = "  the same, taken by a listener (the bridge's design)",
       .type = Type::kCommand,
       .listener = true,
       .period_ns = c,
       .random_gaps = true,
       .writer_qos = [] { return dds::command_writer_qos(partition(), 10, seconds(5)); },
       .reader_qos = [] { return dds::command_reader_qos(partition()); }});
  add({.label = "  the same at ddsperf's rate (500 Hz)",
       .type = Type::kCommand,
       .listener = true,
       .period_ns = 2'000'000,
       .writer_qos = [] { return dds::command_writer_qos(partition(), 10, seconds(5)); },
       .reader_qos = [] { return dds::command_reader_qos(partition()); }});
  add({.label = "PumpState (keyed, strings), ddsperf's QoS, bridge -> supervisor, the commands' "
                "rate",
       .type = Type::kState,
       .peer_writes = false,
       .period_ns = c,
       .random_gaps = true,
       .writer_qos = ddsperf_qos,
       .reader_qos = ddsperf_qos,
       .chained = false});
  add({.label = "  the product's state QoS (transient local, deadline 2 s, order by source time)",
       .type = Type::kState,
       .peer_writes = false,
       .period_ns = c,
       .random_gaps = true,
       .writer_qos = [] { return dds::state_writer_qos(seconds(2)); },
       .reader_qos = [] { return dds::state_reader_qos(); }});
  return p;
}

std::string topic_name(std::size_t path, bool echo) {
  return fmt::format("dnbridge_bench/path{}{}", path, echo ? "_echo" : "");
}

// The measurement schedule, the same in both processes: slot k measures path
// order[k] from starts[k] for `seconds`.
struct Schedule {
  std::vector<std::size_t> order;
  std::vector<std::int64_t> starts;
  std::int64_t end = 0;
};

Schedule make_schedule(const std::vector<Path>& paths, std::int64_t t0, std::int64_t slot_ns,
                       int rounds) {
  Schedule s;
  std::int64_t t = t0;
  for (int r = 0; r < rounds; ++r) {
    for (std::size_t p = 0; p < paths.size(); ++p) {
      s.order.push_back(p);
      s.starts.push_back(t);
      t += slot_ns + kSlotGapNs + (paths[p].ddsperf ? kDdsperfExtraNs : 0);
    }
  }
  s.end = t;
  return s;
}

// ---------------------------------------------------------------------------
// Samples: a sequence number in each, so that a take is matched to its write

struct Record {
  std::uint32_t seq;
  std::int64_t at;       // CLOCK_MONOTONIC
  std::int64_t call_ns;  // writes: how long the write call took
};

// A sample of each type, keyed by seq % kInstances, carrying seq.
template <class T>
struct Stamp;

template <>
struct Stamp<dnbridge_bench_Probe> {
  static void init(dds::Owned<dnbridge_bench_Probe>& s) {
    s->baggage._buffer = dds_sequence_octet_allocbuf(kBaggage);
    s->baggage._length = s->baggage._maximum = kBaggage;
    s->baggage._release = true;
    for (std::size_t i = 0; i < kBaggage; ++i) s->baggage._buffer[i] = static_cast<uint8_t>(i);
  }
  static void set(dnbridge_bench_Probe& s, std::uint32_t seq) {
    s.seq = seq;
    s.keyval = seq % kInstances;
  }
  static std::uint32_t seq(const dnbridge_bench_Probe& s) { return s.seq; }
};

// A command carries 16 bits of sequence number in its analog output.
template <>
struct Stamp<dnbridge_PumpCommand> {
  static void init(dds::Owned<dnbridge_PumpCommand>& s) {
    dds::set_string(s->rack, kRack);
    dds::set_string(s->port, "A");
    dds::set_string(s->issuer, "supervisor-1@plant-host");
  }
  static void set(dnbridge_PumpCommand& s, std::uint32_t seq) {
    s.mac = static_cast<std::uint8_t>(1 + seq % kInstances);
    s.pump_on = seq % 2 == 0;
    s.analog_output_raw = static_cast<std::uint16_t>(seq);
  }
  static std::uint32_t seq(const dnbridge_PumpCommand& s) { return s.analog_output_raw; }
};

// A state carries its sequence number in its two analog inputs.
template <>
struct Stamp<dnbridge_PumpState> {
  static void init(dds::Owned<dnbridge_PumpState>& s) {
    dds::set_string(s->rack, kRack);
    dds::set_string(s->port, "A");
    dds::set_string(s->name, "dry-pump-1");
    dds::set_string(s->idle_reason, "");
    s->online = s->inputs_valid = true;
    s->analog_input_count = 2;
  }
  static void set(dnbridge_PumpState& s, std::uint32_t seq) {
    s.mac = static_cast<std::uint8_t>(1 + seq % kInstances);
    s.analog_input_raw[0] = static_cast<std::uint16_t>(seq & 0xffff);
    s.analog_input_raw[1] = static_cast<std::uint16_t>(seq >> 16);
  }
  static std::uint32_t seq(const dnbridge_PumpState& s) {
    return std::uint32_t{s.analog_input_raw[0]} | std::uint32_t{s.analog_input_raw[1]} << 16;
  }
};

// One path's entities in one process: its writer or its reader (both for
// the round trip, on two topics), what they recorded, and the writes.
class Endpoint {
 public:
  virtual ~Endpoint() = default;
  // Writes samples at the path's pace from `start` until `end`.
  virtual void write_until(std::int64_t start, std::int64_t end, std::uint64_t seed) = 0;
  virtual bool matched() const = 0;
  // Called on the waitset thread when its reader has data.
  virtual void on_data() = 0;
  virtual const dds::Entity* reader() const = 0;
  virtual void detach_listener() = 0;
  std::vector<Record> writes, takes;
  // Writes back (round trip) that failed, on the taking thread.
  std::atomic<std::uint64_t> failed_echoes{0};
};

template <class T>
class TypedEndpoint final : public Endpoint {
 public:
  // `writing`: this process writes on the path's topic, else it takes from
  // it. On a round trip both sides write and take: the taking side
  // (`echoing`) writes every sample back on a second topic, which the
  // writing side takes.
  TypedEndpoint(const dds::Participant& participant, const Path& path, std::size_t index,
                bool writing, bool echoing)
      : path_(path),
        echo_(echoing),
        out_topic_(participant, topic_name(index, !writing)),
        in_topic_(participant, topic_name(index, writing)),
        listener_([this] { on_data(); }),
        buffer_(8) {
    Stamp<T>::init(sample_);
    if (writing || path.round_trip) writer_.emplace(participant, out_topic_, path.writer_qos());
    if (!writing || path.round_trip) {
      // No sample comes before the schedule starts, long after the reader
      // is made: the listener never runs before reader_ is set.
      if (path.listener) {
        reader_.emplace(participant, in_topic_, path.reader_qos(), listener_.get());
        if (!reader_->set_status_mask(DDS_DATA_AVAILABLE_STATUS)) {
          throw std::runtime_error("setting a reader's status mask failed");
        }
      } else {
        reader_.emplace(participant, in_topic_, path.reader_qos());
      }
    }
    writes.reserve(1 << 16);
    takes.reserve(1 << 16);
  }
  ~TypedEndpoint() override { detach_listener(); }

  void write_until(std::int64_t start, std::int64_t end, std::uint64_t seed) override {
    std::mt19937_64 random(seed);
    std::uniform_int_distribution<std::int64_t> gap(path_.period_ns / 2,
                                                    path_.period_ns + path_.period_ns / 2);
    std::int64_t next = start;
    while (next < end) {
      sleep_until_monotonic(next);
      if (!write(next_seq_++)) throw std::runtime_error("a write failed");
      next += path_.random_gaps ? gap(random) : path_.period_ns;
      next = std::max(next, monotonic_ns());
    }
  }
  bool matched() const override {
    if (writer_ && writer_->matched_subscriptions().value_or(0) == 0) return false;
    if (reader_ && reader_->matched_publications().value_or(0) == 0) return false;
    return true;
  }
  void on_data() override {
    for (;;) {
      const auto n = reader_->take(buffer_);
      const auto now = monotonic_ns();
      if (!n || *n == 0) return;
      for (std::size_t i = 0; i < *n; ++i) {
        if (!buffer_.info(i).valid_data()) continue;
        const auto seq = Stamp<T>::seq(buffer_.data(i));
        takes.push_back({seq, now, 0});
        if (echo_ && !write(seq)) failed_echoes.fetch_add(1, std::memory_order_relaxed);
      }
      if (*n < buffer_.capacity()) return;
    }
  }
  const dds::Entity* reader() const override {
    return reader_ && !path_.listener ? &*reader_ : nullptr;
  }
  void detach_listener() override {
    if (reader_ && path_.listener) (void)dds::DataListener::detach(*reader_);
  }

 private:
  bool write(std::uint32_t seq) {
    Stamp<T>::set(*sample_, seq);
    const auto at = monotonic_ns();
    if (!writer_->write(*sample_)) return false;
    writes.push_back({seq, at, monotonic_ns() - at});
    return true;
  }

  const Path& path_;
  bool echo_;  // the side that writes the round trip back
  dds::Topic<T> out_topic_, in_topic_;
  dds::DataListener listener_;
  std::optional<dds::Writer<T>> writer_;
  std::optional<dds::Reader<T>> reader_;
  dds::TakeBuffer<T> buffer_;
  dds::Owned<T> sample_;
  std::uint32_t next_seq_ = 0;
};

// Both processes: every path's endpoint on this side, a waitset thread that
// takes for the waitset paths, the schedule run, and the records.
class Side {
 public:
  Side(int domain, const std::vector<Path>& paths, bool peer)
      : paths_(paths),
        participant_(static_cast<dds_domainid_t>(domain),
                     dds::Participant::ClientName{peer ? "dds-bench-peer" : "dds-bench-bridge"}),
        stop_(participant_),
        waitset_(participant_) {
    for (std::size_t i = 0; i < paths.size(); ++i) {
      const auto& p = paths[i];
      if (p.ddsperf) {
        endpoints_.emplace_back();
        continue;
      }
      const bool writes = p.peer_writes == peer;
      const bool echo = p.round_trip && !peer;
      switch (p.type) {
        case Type::kProbe:
          endpoints_.push_back(std::make_unique<TypedEndpoint<dnbridge_bench_Probe>>(
              participant_, p, i, writes, echo));
          break;
        case Type::kCommand:
          endpoints_.push_back(std::make_unique<TypedEndpoint<dnbridge_PumpCommand>>(
              participant_, p, i, writes, echo));
          break;
        case Type::kState:
          endpoints_.push_back(std::make_unique<TypedEndpoint<dnbridge_PumpState>>(
              participant_, p, i, writes, echo));
          break;
      }
      if (const auto* r = endpoints_.back()->reader()) {
        if (!r->set_status_mask(DDS_DATA_AVAILABLE_STATUS)) {
          throw std::runtime_error("setting a reader's status mask failed");
        }
        waitset_.attach(*r, static_cast<dds::WaitSet::Token>(i));
      }
    }
    waitset_.attach(stop_, kStopToken);
    taker_ = std::thread([this] {
      for (;;) {
        auto triggered = waitset_.wait(milliseconds(200));
        if (!triggered) continue;
        for (auto t : *triggered) {
          if (t == kStopToken) return;
          endpoints_[static_cast<std::size_t>(t)]->on_data();
        }
      }
    });
  }
  ~Side() { stop(); }

  // Every endpoint matched by `deadline`.
  bool wait_matched(std::int64_t deadline) const {
    for (;;) {
      bool all = true;
      for (const auto& e : endpoints_) all = all && (!e || e->matched());
      if (all) return true;
      if (monotonic_ns() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  // Runs the schedule: this side's writes; `on_ddsperf(slot)` for ddsperf's.
  void run(const Schedule& s, std::int64_t slot_ns, bool peer,
           const std::function<void(std::size_t)>& on_ddsperf) {
    for (std::size_t k = 0; k < s.order.size(); ++k) {
      const auto& p = paths_[s.order[k]];
      if (p.ddsperf) {
        if (on_ddsperf) {
          sleep_until_monotonic(s.starts[k]);
          on_ddsperf(k);
        }
        continue;
      }
      if (p.peer_writes == peer) {
        endpoints_[s.order[k]]->write_until(s.starts[k], s.starts[k] + slot_ns, 20261126 + k);
      }
    }
    sleep_until_monotonic(s.end);
  }

  // Stops taking: the records can be read after.
  void stop() {
    if (!taker_.joinable()) return;
    (void)stop_.trigger();
    taker_.join();
    for (auto& e : endpoints_) {
      if (e) e->detach_listener();
    }
  }

  const Endpoint* endpoint(std::size_t path) const { return endpoints_[path].get(); }

 private:
  static constexpr dds::WaitSet::Token kStopToken = -1;
  const std::vector<Path>& paths_;
  dds::Participant participant_;
  dds::GuardCondition stop_;
  dds::WaitSet waitset_;
  std::vector<std::unique_ptr<Endpoint>> endpoints_;
  std::thread taker_;
};

// ---------------------------------------------------------------------------
// The peer: the supervisor's side

struct Options {
  double seconds = 5;
  int rounds = 6;
  int command_interval_us = 10'000;
  int bridge_cpu = 1, peer_cpu = 0;
  bool pin = true;
  bool hold_awake = true;
  bool ddsperf = true;
  int domain = -1;
  // The peer's.
  bool peer = false;
  std::int64_t t0 = 0;
};

std::vector<Path> paths_of(const Options& o) {
  auto paths = make_paths(static_cast<std::int64_t>(o.command_interval_us) * 1000);
  if (!o.ddsperf) paths.erase(paths.begin());
  return paths;
}

std::int64_t slot_ns(const Options& o) { return static_cast<std::int64_t>(o.seconds * 1e9); }

int run_peer(const Options& o) {
  const auto paths = paths_of(o);
  Side side(o.domain, paths, true);
  if (!side.wait_matched(o.t0)) {
    std::fprintf(stderr, "dnbridge-dds-bench peer: not every path matched before the start\n");
    return 1;
  }
  const auto schedule = make_schedule(paths, o.t0, slot_ns(o), o.rounds);
  side.run(schedule, slot_ns(o), true, {});
  side.stop();
  std::string out;
  for (std::size_t p = 0; p < paths.size(); ++p) {
    const auto* e = side.endpoint(p);
    if (!e) continue;
    for (const auto& r : e->writes)
      out += fmt::format("w {} {} {} {}\n", p, r.seq, r.at, r.call_ns);
    for (const auto& r : e->takes) out += fmt::format("t {} {} {}\n", p, r.seq, r.at);
  }
  out += "done\n";
  std::fwrite(out.data(), 1, out.size(), stdout);
  std::fflush(stdout);
  return 0;
}

// ---------------------------------------------------------------------------
// This side: the schedule, and the figures

struct PeerRecords {
  std::map<std::size_t, std::vector<Record>> writes, takes;
};

PeerRecords read_peer(Child child, std::int64_t deadline) {
  PeerRecords r;
  read_child_output(child, deadline, "peer", [&](const std::string& line) {
    char kind = 0;
    std::size_t path = 0;
    unsigned long seq = 0;
    long long at = 0, call = 0;
    if (std::sscanf(line.c_str(), "%c %zu %lu %lld %lld", &kind, &path, &seq, &at, &call) >= 4) {
      (kind == 'w' ? r.writes : r.takes)[path].push_back({static_cast<std::uint32_t>(seq),
                                                          static_cast<std::int64_t>(at),
                                                          static_cast<std::int64_t>(call)});
    }
  });
  return r;
}

// Latencies (us) from writes to the takes of the same sequence numbers, each
// also put in the slot (round) its write fell in. `lost`: writes never taken.
struct Latencies {
  std::vector<double> all;
  std::vector<std::vector<double>> by_round;
  std::size_t lost = 0;
};

Latencies match(const std::vector<Record>& writes, const std::vector<Record>& takes,
                const std::vector<std::int64_t>& round_starts, double scale = 1.0) {
  Latencies l;
  l.by_round.resize(round_starts.size());
  std::map<std::uint32_t, std::int64_t> taken;
  for (const auto& t : takes) taken.emplace(t.seq, t.at);
  for (const auto& w : writes) {
    auto it = taken.find(w.seq);
    if (it == taken.end()) {
      ++l.lost;
      continue;
    }
    const double us = static_cast<double>(it->second - w.at) / 1e3 * scale;
    l.all.push_back(us);
    std::size_t round = 0;
    while (round + 1 < round_starts.size() && w.at >= round_starts[round + 1]) ++round;
    l.by_round[round].push_back(us);
  }
  return l;
}

std::string us(double v) { return fmt::format("{:.1f}", v); }

// Every command path writes fewer commands than its 16-bit sequence numbers
// tell apart.
void check_sequence_numbers(const std::vector<Path>& paths, const Options& o) {
  for (const auto& p : paths) {
    const auto shortest_gap = static_cast<double>(p.random_gaps ? p.period_ns / 2 : p.period_ns);
    if (p.type == Type::kCommand && o.seconds * 1e9 / shortest_gap * o.rounds >= 65536) {
      throw std::runtime_error(fmt::format(
          "\"{}\" would write more commands than their 16-bit sequence numbers tell apart: "
          "lower --seconds or --rounds",
          p.label));
    }
  }
}

// The command line that re-executes this program as the peer.
std::vector<std::string> peer_args(const Options& o, int domain, std::int64_t t0) {
  std::vector<std::string> args{"/proc/self/exe",
                                "--peer",
                                "--domain",
                                std::to_string(domain),
                                "--t0",
                                std::to_string(t0),
                                "--seconds",
                                fmt::format("{}", o.seconds),
                                "--rounds",
                                std::to_string(o.rounds),
                                "--command-interval-us",
                                std::to_string(o.command_interval_us)};
  if (!o.ddsperf) args.push_back("--no-ddsperf");
  return args;
}

// Round starts, for the per-round figures.
std::vector<std::int64_t> round_starts(const Schedule& schedule, int rounds, std::size_t paths) {
  std::vector<std::int64_t> starts;
  for (int r = 0; r < rounds; ++r)
    starts.push_back(schedule.starts[static_cast<std::size_t>(r) * paths]);
  return starts;
}

// The table of figures (Markdown), a row a path.
class Table {
 public:
  Table() {
    fmt::print(
        "| path | samples | p50 us | p99 us | max us | p99 by round us | p99 / ddsperf p99 | "
        "p50, p99 change from the row above us | write() p50 us |\n");
    fmt::print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  }

  // A path's one-way latencies; `chain`: with their change from the row above.
  void row(const std::string& label, const Latencies& l, std::optional<double> write_p50,
           bool chain) {
    const auto s = summarize(l.all);
    std::string by_round;
    for (const auto& r : l.by_round) {
      by_round += (by_round.empty() ? "" : " / ") + (r.empty() ? "-" : us(summarize(r).p99));
    }
    // A row that is not chained starts a chain: the reference of the rows
    // below it.
    const auto change =
        chain && above_ ? fmt::format("{:+.1f}, {:+.1f}", s.p50 - above_->p50, s.p99 - above_->p99)
                        : std::string();
    fmt::print("| {} | {}{} | {} | {} | {} | {} | {} | {} | {} |\n", label, s.count,
               l.lost ? fmt::format(" ({} lost)", l.lost) : "", us(s.p50), us(s.p99), us(s.max),
               by_round, ddsperf_p99_ > 0 ? fmt::format("{:.2f}", s.p99 / ddsperf_p99_) : "",
               change, write_p50 ? us(*write_p50) : "");
    above_ = s;
  }

  // ddsperf's row, its windows of every round pooled: the reference of the
  // rows' p99 ratios.
  void ddsperf_row(const std::string& label, const std::vector<DdsperfResult>& ddsperf) {
    std::vector<DdsperfWindow> windows;
    for (const auto& d : ddsperf) windows.insert(windows.end(), d.windows.begin(), d.windows.end());
    double count = 0, max = 0;
    for (const auto& w : windows) {
      count += w.count;
      max = std::max(max, w.max);
    }
    // ddsperf prints its round trips halved already (see ddsperf.hpp).
    ddsperf_p99_ = pooled_quantile(windows, 0.99);
    std::string by_round;
    for (const auto& d : ddsperf) {
      by_round += (by_round.empty() ? "" : " / ") + us(d.half_rtt_p99);
    }
    fmt::print("| {} | {:.0f} | {} | {} | {} | {} | 1.00 | | |\n", label, count,
               us(pooled_quantile(windows, 0.5)), us(ddsperf_p99_), us(max), by_round);
  }

 private:
  double ddsperf_p99_ = 0;
  std::optional<Summary> above_;
};

// Every path's row, in the paths' order.
void print_table(const std::vector<Path>& paths, const std::vector<DdsperfResult>& ddsperf,
                 const Side& side, const PeerRecords& peer_records,
                 const std::vector<std::int64_t>& rounds) {
  Table table;
  for (std::size_t p = 0; p < paths.size(); ++p) {
    const auto& path = paths[p];
    if (path.ddsperf) {
      table.ddsperf_row(path.label, ddsperf);
      continue;
    }
    const auto* mine = side.endpoint(p);
    const auto& peer_writes =
        peer_records.writes.count(p) ? peer_records.writes.at(p) : std::vector<Record>{};
    const auto& peer_takes =
        peer_records.takes.count(p) ? peer_records.takes.at(p) : std::vector<Record>{};
    const auto& writes = path.peer_writes ? peer_writes : mine->writes;
    std::vector<double> calls;
    for (const auto& w : writes) calls.push_back(static_cast<double>(w.call_ns) / 1e3);
    const auto call_p50 = summarize(calls).p50;
    if (path.round_trip) {
      table.row(path.label, match(peer_writes, peer_takes, rounds, 0.5), call_p50, false);
      table.row("  its first leg (supervisor -> bridge), one way",
                match(peer_writes, mine->takes, rounds), std::nullopt, false);
      // The second leg: from the take on this side, which writes it back at once.
      table.row("  its second leg (take, write back, take), one way",
                match(mine->takes, peer_takes, rounds), std::nullopt, false);
      continue;
    }
    table.row(path.label,
              path.peer_writes ? match(peer_writes, mine->takes, rounds)
                               : match(mine->writes, peer_takes, rounds),
              call_p50, path.chained);
  }
}

int run_bench(const Options& o) {
  const int domain = o.domain >= 0 ? o.domain : 170 + static_cast<int>(getpid() % 30);
  const std::string tag = fmt::format("dnbridge-dds-bench-{}", getpid());
  setenv("CYCLONEDDS_URI", dds::loopback_config(tag).c_str(), 1);
  const auto paths = paths_of(o);
  check_sequence_numbers(paths, o);

  print_run_header("dnbridge DDS benchmark", domain, tag);
  const int awake = o.hold_awake ? hold_cpus_awake() : -1;
  fmt::print("CPU idle: {}\n", awake >= 0 ? "/dev/cpu_dma_latency held at 0 us (no CPU halts)"
                                          : "CPUs halt when idle");
  const Placement cpus = place_processes(o.pin, o.bridge_cpu, o.peer_cpu, "the bridge's side",
                                         "the supervisor's side");
  fmt::print(
      "{} rounds of {} paths, {:.1f} s each; commands and states every {} us on average "
      "(gaps 0.5..1.5 x), round robin over {} instances\n\n",
      o.rounds, paths.size(), o.seconds, o.command_interval_us, kInstances);

  Side side(domain, paths, false);
  const auto t0 = monotonic_ns() + 5'000'000'000;
  const auto schedule = make_schedule(paths, t0, slot_ns(o), o.rounds);
  const auto args = peer_args(o, domain, t0);
  Child peer = spawn_child(args, true, cpus.peer);
  if (!side.wait_matched(t0)) {
    kill(peer.pid, SIGKILL);
    (void)wait_child(peer.pid);
    throw std::runtime_error("not every path matched within 5 s");
  }
  std::vector<DdsperfResult> ddsperf;
  try {
    side.run(schedule, slot_ns(o), false, [&](std::size_t slot) {
      Ddsperf run(domain, o.seconds, 500, 128, cpus);
      ddsperf.push_back(run.finish());
      // Its start-up is not bounded by its own run time: one that ran into
      // the next slot would have measured beside it.
      const auto next =
          slot + 1 < schedule.starts.size() ? schedule.starts[slot + 1] : schedule.end;
      if (monotonic_ns() > next) {
        throw std::runtime_error("ddsperf ran past its slot (it took long to find its pong)");
      }
    });
  } catch (...) {
    kill(peer.pid, SIGKILL);
    (void)wait_child(peer.pid);
    close(peer.out);
    throw;
  }
  side.stop();
  const auto peer_records = read_peer(peer, monotonic_ns() + 60'000'000'000);
  for (std::size_t p = 0; p < paths.size(); ++p) {
    if (const auto* e = side.endpoint(p); e && e->failed_echoes.load() > 0) {
      throw std::runtime_error(
          fmt::format("{} writes back of \"{}\" failed", e->failed_echoes.load(), paths[p].label));
    }
  }
  fmt::print("load average at end: {}\n\n", load_average());

  print_table(paths, ddsperf, side, peer_records, round_starts(schedule, o.rounds, paths.size()));
  if (awake >= 0) close(awake);
  return 0;
}

}  // namespace
}  // namespace dnbridge::bench

int main(int argc, char** argv) {
  using namespace dnbridge::bench;
  Options o;
  CLI::App app{
      "dnbridge-dds-bench: what the product's type, QoS and way of taking cost Cyclone DDS, "
      "one change at a time from ddsperf's set-up"};
  app.add_option("--seconds", o.seconds, "length of one path's slot")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  app.add_option("--rounds", o.rounds, "times every path is measured")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--command-interval-us", o.command_interval_us,
                 "mean gap between two commands (or states)")
      ->check(CLI::Range(2, 10'000'000))
      ->capture_default_str();
  app.add_option("--bridge-cpu", o.bridge_cpu, "CPU of this process and ddsperf pong")
      ->capture_default_str();
  app.add_option("--peer-cpu", o.peer_cpu, "CPU of the peer process and ddsperf ping")
      ->capture_default_str();
  app.add_flag("!--no-pin", o.pin, "let the kernel place every process");
  app.add_flag("!--allow-idle", o.hold_awake, "let CPUs halt when idle");
  app.add_flag("!--no-ddsperf", o.ddsperf, "leave ddsperf out");
  app.add_option("--domain", o.domain, "DDS domain (default: from the process id)");
  app.add_flag("--peer", o.peer)->group("");  // the re-executed peer
  app.add_option("--t0", o.t0)->group("");
  CLI11_PARSE(app, argc, argv);
  try {
    return o.peer ? run_peer(o) : run_bench(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dnbridge-dds-bench: %s\n", e.what());
    return 1;
  }
}
