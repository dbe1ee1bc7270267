// dnbridge-load-bench: what load through DDS costs the real dnbridge
// executable, run as a child process on its embedded default configuration
// (8 simulated CDN127s on port "A" of rack "sim-rack", polled every 100 ms,
// publish policy as shipped), with the load written by this process through
// a DDS participant of its own, QoS from adapters/dds/topics.hpp.
//
// Scenarios, each for a fixed time:
//   idle: no load (the baseline);
//   (a) explicit requests: COMMAND_EXECUTE of Get_Attribute_Single Identity
//       instance 1 attribute 1 (vendor ID), nodes 1..8 in turn, one txid
//       each, each request instance unregistered once its reply is taken (as
//       a well-behaved requester does); at 100/s and 1000/s;
//   (b) PumpCommand writes, round robin over the 8 pumps, each pump's outputs
//       alternating between two values; at 1 kHz and 10 kHz;
//   (b') on request (--same-command-rates), the same writes with outputs that
//       never change, as a supervisor that rewrites its commands sends: what
//       the DDS path costs without the polls and PumpStates that changes
//       cause.
// For each: requests answered/sent (by status) and reply latency (written ->
// reply taken), polls per node per second (NodeStatus counters), PumpState
// freshness (take time - source timestamp) and the longest gap between two
// samples of a pump, the bridge's CPU time (/proc/PID/stat utime + stime,
// and by thread) and its RSS before and after.
//
// The bridge has a DDS domain and a discovery tag of this run's own, on the
// loopback interface only. Load is paced with clock_nanosleep; everything
// else waits for events (DDS waitsets, the bridge's exit through a pidfd).
// It reports figures; it exits non-zero only when the run itself fails.
#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/loopback.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"
#include "bench_process.hpp"
#include "figures.hpp"

namespace dnbridge::bench {
namespace {

// What the embedded default configuration has (dnbridge --print-default-config).
constexpr const char* kRack = "sim-rack";
constexpr const char* kPort = "A";
constexpr unsigned kNodes = 8;  // MACs 1..8

// IDL constants (idl/dnbridge.idl).
constexpr std::uint8_t kCommandExecute = 1;
constexpr std::uint8_t kStatusSuccess = 1;
constexpr std::uint8_t kStatusInProgress = 2;

// CIP: Get_Attribute_Single of Identity (class 1) instance 1 attribute 1.
constexpr std::uint8_t kGetAttributeSingle = 0x0E;
constexpr std::uint16_t kIdentityClass = 1;

// Lines of the bridge's log by level, from `offset` on ("TIME LEVEL component:
// message", adapters/daemon/log_sink.cpp). Returns the new offset.
struct LogCounts {
  unsigned warn = 0, error = 0;
  std::string first;  // the first warning or error
};
std::streamoff count_log(const std::filesystem::path& path, std::streamoff offset, LogCounts& c) {
  std::ifstream f(path);
  f.seekg(offset);
  std::string line;
  std::streamoff end = offset;
  while (std::getline(f, line)) {
    end += static_cast<std::streamoff>(line.size() + 1);
    std::istringstream words(line);
    std::string time, level;
    words >> time >> level;
    if (level == "warn" || level == "error") {
      (level == "warn" ? c.warn : c.error)++;
      if (c.first.empty()) c.first = line.substr(0, 200);
    }
  }
  return end;
}

// ---------------------------------------------------------------------------
// The load's DDS side: a participant with the writers of the load and the
// readers of everything the bridge publishes, taken on a waitset thread.

// What the readers saw during one measurement window.
struct Observed {
  std::int64_t from = 0, to = 0;  // monotonic ns
  // PumpState
  std::vector<double> freshness_us;  // take (wall) - source timestamp
  std::uint64_t pump_samples = 0;
  std::array<std::int64_t, kNodes + 1> last_pump_take{};  // monotonic ns, per MAC
  std::array<double, kNodes + 1> max_gap_us{};
  // NodeStatus, first and last sample of each node in the window
  struct Counters {
    std::int64_t at = 0;  // taken, monotonic ns
    dnbridge_NodeCounters c{};
  };
  std::array<std::optional<Counters>, kNodes + 1> first_counters, last_counters;
  // PortStatus, the last sample
  std::optional<dnbridge_PortStatus> port;  // strings not kept
};

class Load {
 public:
  Load(int domain, std::string requester, std::size_t max_requests)
      : requester_(std::move(requester)),
        participant_(static_cast<dds_domainid_t>(domain),
                     dds::Participant::ClientName{"dnbridge-load-bench"}),
        pump_topic_(participant_),
        node_topic_(participant_),
        port_topic_(participant_),
        command_topic_(participant_),
        request_topic_(participant_),
        reply_topic_(participant_),
        pump_reader_(participant_, pump_topic_, dds::state_reader_qos()),
        node_reader_(participant_, node_topic_, dds::state_reader_qos()),
        port_reader_(participant_, port_topic_, dds::state_reader_qos()),
        reply_reader_(participant_, reply_topic_,
                      dds::reply_reader_qos(dds::rack_partitions(kRack))),
        command_writer_(participant_, command_topic_,
                        dds::command_writer_qos(dds::rack_partitions(kRack), 10, seconds(5))),
        request_writer_(participant_, request_topic_,
                        dds::request_writer_qos(dds::rack_partitions(kRack))),
        pump_buffer_(32),
        node_buffer_(16),
        port_buffer_(4),
        reply_buffer_(64),
        stop_(participant_),
        waitset_(participant_),
        written_at_(max_requests + 1),
        replied_at_(max_requests + 1),
        reply_status_(max_requests + 1),
        reply_general_(max_requests + 1) {
    // Readers wake the waitset on data; the writers and the reply reader also
    // on matching, which the waiter for readiness needs to hear of. Each
    // status read below resets its trigger.
    auto mask = [](const dds::Entity& e, uint32_t m) {
      if (!e.set_status_mask(m)) throw std::runtime_error("setting a status mask failed");
    };
    mask(pump_reader_, DDS_DATA_AVAILABLE_STATUS);
    mask(node_reader_, DDS_DATA_AVAILABLE_STATUS);
    mask(port_reader_, DDS_DATA_AVAILABLE_STATUS);
    mask(reply_reader_, DDS_DATA_AVAILABLE_STATUS | DDS_SUBSCRIPTION_MATCHED_STATUS);
    mask(command_writer_, DDS_PUBLICATION_MATCHED_STATUS);
    mask(request_writer_, DDS_PUBLICATION_MATCHED_STATUS);
    waitset_.attach(pump_reader_, kPumpState);
    waitset_.attach(node_reader_, kNodeStatus);
    waitset_.attach(port_reader_, kPortStatus);
    waitset_.attach(reply_reader_, kReplies);
    waitset_.attach(command_writer_, kCommandMatched);
    waitset_.attach(request_writer_, kRequestMatched);
    waitset_.attach(stop_, kStop);

    for (unsigned mac = 1; mac <= kNodes; ++mac) {
      auto& c = commands_[mac];
      dds::set_string(c->rack, kRack);
      dds::set_string(c->port, kPort);
      c->mac = static_cast<std::uint8_t>(mac);
      dds::set_string(c->issuer, "dnbridge-load-bench");
    }
    dds::set_string(request_->requester, requester_);
    request_->command = kCommandExecute;
    dds::set_string(request_->rack, kRack);
    dds::set_string(request_->port, kPort);
    request_->service = kGetAttributeSingle;
    request_->class_id = kIdentityClass;
    request_->instance_id = 1;
    request_->has_attribute = true;
    request_->attribute_id = 1;
    dds::set_string(request_key_->requester, requester_);

    thread_ = std::thread([this] { run(); });
  }
  ~Load() { stop(); }
  Load(const Load&) = delete;
  Load& operator=(const Load&) = delete;

  void stop() {
    if (!thread_.joinable()) return;
    (void)stop_.trigger();
    thread_.join();
  }

  // Until every node is online with its inputs read and the bridge's
  // command and request readers and reply writer are matched; false when
  // `deadline` (monotonic ns) passes first or the bridge ends.
  template <class Alive>
  bool wait_ready(std::int64_t deadline, Alive alive) {
    std::unique_lock lock(mutex_);
    for (;;) {
      if (ready_nodes_ == kNodes && command_matched_ && request_matched_ && reply_matched_) {
        return true;
      }
      const auto now = monotonic_ns();
      if (now >= deadline || !alive()) return false;
      // Woken by the waitset thread on every change; the bound is only for
      // noticing a bridge that exited.
      changed_.wait_for(lock, std::chrono::milliseconds(
                                  std::min<std::int64_t>((deadline - now) / 1'000'000 + 1, 500)));
    }
  }
  std::string readiness() {
    std::lock_guard lock(mutex_);
    return fmt::format(
        "{} of {} nodes online with inputs; command reader {}, request reader {}, reply writer {}",
        ready_nodes_, kNodes, command_matched_ ? "matched" : "not matched",
        request_matched_ ? "matched" : "not matched", reply_matched_ ? "matched" : "not matched");
  }

  // Measurement windows of what the readers see.
  void begin_window() {
    std::lock_guard lock(mutex_);
    window_ = Observed{};
    window_.from = monotonic_ns();
    windowing_ = true;
  }
  Observed end_window() {
    std::lock_guard lock(mutex_);
    windowing_ = false;
    window_.to = monotonic_ns();
    return std::move(window_);
  }

  // --- Explicit requests (the main thread) --------------------------------
  std::uint32_t next_txid() const { return next_txid_; }
  std::size_t capacity() const { return written_at_.size() - 1; }
  // Writes the next request (txid next_txid()) to `mac`; false when the
  // write failed (the txid is then not used).
  bool request(unsigned mac) {
    if (next_txid_ >= written_at_.size()) return false;
    request_->txid = next_txid_;
    request_->mac = static_cast<std::uint8_t>(mac);
    written_at_[next_txid_].store(monotonic_ns(), std::memory_order_release);
    if (!request_writer_.write(*request_)) {
      written_at_[next_txid_].store(0, std::memory_order_relaxed);
      return false;
    }
    ++next_txid_;
    return true;
  }
  // Until txids [first, last) are all answered or `deadline` passes (the
  // waitset thread notifies on every reply).
  void wait_answered(std::uint32_t first, std::uint32_t last, std::int64_t deadline) {
    std::unique_lock lock(mutex_);
    for (;;) {
      std::uint32_t open = 0;
      for (std::uint32_t t = first; t < last; ++t) {
        if (written_at_[t].load(std::memory_order_relaxed) != 0 &&
            replied_at_[t].load(std::memory_order_acquire) == 0) {
          ++open;
        }
      }
      const auto now = monotonic_ns();
      if (open == 0 || now >= deadline) return;
      changed_.wait_for(lock, std::chrono::nanoseconds(deadline - now));
    }
  }
  struct Replies {
    std::uint64_t sent = 0, answered = 0;
    std::map<std::uint8_t, std::uint64_t> by_status;
    std::uint64_t device_success = 0;  // status 1 with CIP general status 0
    std::vector<double> latency_us;
  };
  Replies replies(std::uint32_t first, std::uint32_t last) {
    Replies r;
    for (std::uint32_t t = first; t < last; ++t) {
      const auto w = written_at_[t].load(std::memory_order_acquire);
      if (w == 0) continue;
      ++r.sent;
      const auto at = replied_at_[t].load(std::memory_order_acquire);
      if (at == 0) {
        // Given up: a well-behaved requester lets the transaction go.
        std::lock_guard lock(key_mutex_);
        request_key_->txid = t;
        (void)request_writer_.unregister_instance(*request_key_);
        continue;
      }
      ++r.answered;
      const auto status = reply_status_[t].load(std::memory_order_relaxed);
      ++r.by_status[status];
      if (status == kStatusSuccess && reply_general_[t].load(std::memory_order_relaxed) == 0) {
        ++r.device_success;
      }
      r.latency_us.push_back(static_cast<double>(at - w) / 1e3);
    }
    return r;
  }

  // --- Pump commands (the main thread) --------------------------------------
  bool command(unsigned mac, bool pump_on, std::uint16_t analog) {
    auto& c = commands_[mac];
    c->pump_on = pump_on;
    c->analog_output_raw = analog;
    return static_cast<bool>(command_writer_.write(*c));
  }

 private:
  enum Token : dds::WaitSet::Token {
    kPumpState = 1,
    kNodeStatus,
    kPortStatus,
    kReplies,
    kCommandMatched,
    kRequestMatched,
    kStop
  };

  template <class T, class Fn>
  void take_all(const dds::Reader<T>& reader, dds::TakeBuffer<T>& buffer, Fn fn) {
    for (;;) {
      auto taken = reader.take(buffer);
      if (!taken) return;
      const auto mono = monotonic_ns();
      const auto wall = dds::dds_now();
      for (std::size_t i = 0; i < *taken; ++i) fn(buffer.data(i), buffer.info(i), mono, wall);
      if (*taken < buffer.capacity()) return;
    }
  }

  static bool ours(const char* rack, const char* port, unsigned mac) {
    return dds::view(rack) == kRack && dds::view(port) == kPort && mac >= 1 && mac <= kNodes;
  }

  void run() {
    std::array<bool, kNodes + 1> ready{};
    for (;;) {
      auto triggered = waitset_.wait(seconds(1));
      if (!triggered) continue;
      bool changed = false;
      for (auto token : *triggered) {
        switch (token) {
          case kStop:
            return;
          case kPumpState:
            take_all(pump_reader_, pump_buffer_,
                     [&](const dnbridge_PumpState& s, const dds::SampleInfo& info,
                         std::int64_t mono, dds::Timestamp wall) {
                       if (!info.valid_data() || !ours(s.rack, s.port, s.mac)) return;
                       const bool is_ready = s.online && s.inputs_valid;
                       std::lock_guard lock(mutex_);
                       if (is_ready != ready[s.mac]) {
                         ready[s.mac] = is_ready;
                         ready_nodes_ = is_ready ? ready_nodes_ + 1 : ready_nodes_ - 1;
                         changed = true;
                       }
                       if (!windowing_) return;
                       ++window_.pump_samples;
                       window_.freshness_us.push_back(
                           static_cast<double>((wall - info.source_timestamp()).count()) / 1e3);
                       auto& last = window_.last_pump_take[s.mac];
                       if (last != 0) {
                         window_.max_gap_us[s.mac] = std::max(
                             window_.max_gap_us[s.mac], static_cast<double>(mono - last) / 1e3);
                       }
                       last = mono;
                     });
            break;
          case kNodeStatus:
            take_all(node_reader_, node_buffer_,
                     [&](const dnbridge_NodeStatus& s, const dds::SampleInfo& info,
                         std::int64_t mono, dds::Timestamp) {
                       if (!info.valid_data() || !ours(s.rack, s.port, s.mac)) return;
                       std::lock_guard lock(mutex_);
                       if (!windowing_) return;
                       const Observed::Counters c{mono, s.counters};
                       if (!window_.first_counters[s.mac]) window_.first_counters[s.mac] = c;
                       window_.last_counters[s.mac] = c;
                     });
            break;
          case kPortStatus:
            take_all(port_reader_, port_buffer_,
                     [&](const dnbridge_PortStatus& s, const dds::SampleInfo& info, std::int64_t,
                         dds::Timestamp) {
                       if (!info.valid_data() || dds::view(s.rack) != kRack ||
                           dds::view(s.port) != kPort) {
                         return;
                       }
                       std::lock_guard lock(mutex_);
                       if (!windowing_) return;
                       dnbridge_PortStatus copy = s;
                       copy.rack = copy.port = copy.can_interface = copy.reason = nullptr;
                       window_.port = copy;
                     });
            break;
          case kReplies:
            take_all(reply_reader_, reply_buffer_,
                     [&](const dnbridge_ExplicitReply& r, const dds::SampleInfo& info,
                         std::int64_t mono, dds::Timestamp) {
                       // Invalid samples: the bridge's writer left.
                       if (!info.valid_data() || dds::view(r.requester) != requester_) return;
                       if (r.txid == 0 || r.txid >= replied_at_.size()) return;
                       if (r.status == kStatusInProgress) return;  // the final reply follows
                       if (replied_at_[r.txid].load(std::memory_order_relaxed) != 0) return;
                       reply_status_[r.txid].store(r.status, std::memory_order_relaxed);
                       reply_general_[r.txid].store(r.general_status, std::memory_order_relaxed);
                       replied_at_[r.txid].store(mono, std::memory_order_release);
                       // Done with the transaction: its request instance goes.
                       {
                         std::lock_guard lock(key_mutex_);
                         request_key_->txid = r.txid;
                         (void)request_writer_.unregister_instance(*request_key_);
                       }
                       changed = true;
                     });
            if (auto m = reply_reader_.matched_publications()) {
              std::lock_guard lock(mutex_);
              changed = changed || reply_matched_ != (*m > 0);
              reply_matched_ = *m > 0;
            }
            break;
          case kCommandMatched:
            if (auto m = command_writer_.matched_subscriptions()) {
              std::lock_guard lock(mutex_);
              command_matched_ = *m > 0;
              changed = true;
            }
            break;
          case kRequestMatched:
            if (auto m = request_writer_.matched_subscriptions()) {
              std::lock_guard lock(mutex_);
              request_matched_ = *m > 0;
              changed = true;
            }
            break;
          default:
            break;
        }
      }
      if (changed) {
        // Through the mutex, so that a waiter between its check and its
        // wait cannot miss it.
        { std::lock_guard lock(mutex_); }
        changed_.notify_all();
      }
    }
  }

  std::string requester_;
  dds::Participant participant_;
  dds::Topic<dnbridge_PumpState> pump_topic_;
  dds::Topic<dnbridge_NodeStatus> node_topic_;
  dds::Topic<dnbridge_PortStatus> port_topic_;
  dds::Topic<dnbridge_PumpCommand> command_topic_;
  dds::Topic<dnbridge_ExplicitRequest> request_topic_;
  dds::Topic<dnbridge_ExplicitReply> reply_topic_;
  dds::Reader<dnbridge_PumpState> pump_reader_;
  dds::Reader<dnbridge_NodeStatus> node_reader_;
  dds::Reader<dnbridge_PortStatus> port_reader_;
  dds::Reader<dnbridge_ExplicitReply> reply_reader_;
  dds::Writer<dnbridge_PumpCommand> command_writer_;
  dds::Writer<dnbridge_ExplicitRequest> request_writer_;
  dds::TakeBuffer<dnbridge_PumpState> pump_buffer_;
  dds::TakeBuffer<dnbridge_NodeStatus> node_buffer_;
  dds::TakeBuffer<dnbridge_PortStatus> port_buffer_;
  dds::TakeBuffer<dnbridge_ExplicitReply> reply_buffer_;
  dds::GuardCondition stop_;
  dds::WaitSet waitset_;

  std::array<dds::Owned<dnbridge_PumpCommand>, kNodes + 1> commands_;
  dds::Owned<dnbridge_ExplicitRequest> request_;
  std::mutex key_mutex_;  // request_key_: the main thread and the waitset thread
  dds::Owned<dnbridge_ExplicitRequest> request_key_;
  std::uint32_t next_txid_ = 1;
  // Per txid (index), monotonic ns; 0: not written / not answered.
  std::vector<std::atomic<std::int64_t>> written_at_;
  std::vector<std::atomic<std::int64_t>> replied_at_;
  std::vector<std::atomic<std::uint8_t>> reply_status_;
  std::vector<std::atomic<std::uint8_t>> reply_general_;

  std::mutex mutex_;  // everything below
  std::condition_variable changed_;
  unsigned ready_nodes_ = 0;
  bool command_matched_ = false, request_matched_ = false, reply_matched_ = false;
  bool windowing_ = false;
  Observed window_;

  std::thread thread_;
};

// ---------------------------------------------------------------------------
// Scenarios

struct Options {
  std::string dnbridge = DNBRIDGE_EXECUTABLE;
  double seconds = 15;
  double idle_seconds = 10;
  std::vector<int> request_rates{100, 1000};
  std::vector<int> command_rates{1000, 10000};
  std::vector<int> same_command_rates;
  double reply_wait_seconds = 5;
  int domain = -1;
  int bridge_cpu = -1;
  int load_cpu = -1;
  double command_target_percent = 10;
};

// kSameCommands: PumpCommands that never change a pump's outputs, as a
// supervisor that rewrites its commands sends: the DDS path alone.
enum class Kind { kIdle, kRequests, kCommands, kSameCommands };

struct Result {
  std::string name;
  Kind kind = Kind::kIdle;
  int rate = 0;
  double wall_s = 0;
  double cpu_percent = 0;
  std::uint64_t rss_before = 0, rss_after = 0;
  std::uint64_t sent = 0, answered = 0, device_success = 0;
  Summary reply;
  double polls_per_node = 0;
  Summary freshness;
  double max_gap_us = 0;
};

// Writes at `rate` per second for `seconds`, paced on CLOCK_MONOTONIC:
// `write(i)` for the i-th; late writes are made at once (the count, not the
// spacing, is kept). Returns the number of calls.
template <class Write>
std::uint64_t paced(int rate, double seconds, Write write) {
  const std::int64_t start = monotonic_ns();
  const std::int64_t end = start + static_cast<std::int64_t>(seconds * 1e9);
  const double period_ns = 1e9 / rate;
  std::uint64_t i = 0;
  for (;; ++i) {
    const auto due = start + static_cast<std::int64_t>(static_cast<double>(i) * period_ns);
    if (due >= end) break;
    if (due > monotonic_ns()) sleep_until_monotonic(due);
    write(i);
  }
  return i;
}

void print_threads(const ProcessSample& a, const ProcessSample& b, double wall_s) {
  struct Row {
    std::string name;
    double cpu = 0, switches = 0;
    unsigned threads = 0;
  };
  std::map<std::string, Row> rows;  // threads of one name together
  for (const auto& [tid, t1] : b.threads) {
    auto it = a.threads.find(tid);
    const std::uint64_t ticks0 = it == a.threads.end() ? 0 : it->second.ticks;
    const std::uint64_t sw0 = it == a.threads.end() ? 0 : it->second.switches;
    Row& r = rows[t1.name];
    r.name = t1.name;
    r.cpu += core_percent(t1.ticks - ticks0, wall_s);
    r.switches += static_cast<double>(t1.switches - sw0) / wall_s;
    ++r.threads;
  }
  std::vector<Row> sorted;
  sorted.reserve(rows.size());
  for (auto& [name, r] : rows) sorted.push_back(r);
  std::sort(sorted.begin(), sorted.end(), [](const Row& x, const Row& y) {
    return x.cpu != y.cpu ? x.cpu > y.cpu : x.switches > y.switches;
  });
  fmt::print("    by thread (% of one core, context switches/s):\n");
  for (const auto& r : sorted) {
    if (r.cpu < 0.05 && r.switches < 1) continue;
    fmt::print("      {:<18} {:5.1f} %  {:8.0f}/s\n",
               r.threads > 1 ? fmt::format("{} (x{})", r.name, r.threads) : r.name, r.cpu,
               r.switches);
  }
}

class Runner {
 public:
  Runner(const Options& o, BridgeProcess& bridge, Load& load)
      : o_(o), bridge_(bridge), load_(load) {}

  Result run(Kind kind, int rate) {
    Result r = announce(kind, rate);
    const double seconds = kind == Kind::kIdle ? o_.idle_seconds : o_.seconds;

    LogCounts logs;
    log_offset_ = count_log(bridge_.log_path(), log_offset_, logs);  // before: not counted
    logs = {};
    const std::uint32_t first_txid = load_.next_txid();
    load_.begin_window();
    const ProcessSample before = sample_process(bridge_.pid());
    const Writes writes = write_load(kind, rate, seconds);
    const ProcessSample after = sample_process(bridge_.pid());
    const Observed seen = load_.end_window();
    if (auto ended = bridge_.ended()) {
      throw std::runtime_error(fmt::format("dnbridge ended during the scenario ({}); its log: {}",
                                           *ended, bridge_.log_path().string()));
    }
    r.wall_s = static_cast<double>(after.at - before.at) / 1e9;
    r.cpu_percent = core_percent(after.ticks - before.ticks, r.wall_s);
    r.rss_before = before.rss_kb;
    r.rss_after = after.rss_kb;

    if (kind == Kind::kRequests) {
      report_requests(first_txid, writes.failed, r);
    } else if (kind == Kind::kCommands || kind == Kind::kSameCommands) {
      fmt::print("    commands written {} ({:.1f}/s; {} writes failed)\n",
                 writes.written - writes.failed,
                 static_cast<double>(writes.written - writes.failed) / r.wall_s, writes.failed);
    }
    report_node_counters(seen, r);
    report_states(seen, r);
    report_cpu(kind, before, after, writes, r);
    log_offset_ = count_log(bridge_.log_path(), log_offset_, logs);
    fmt::print("    bridge log meanwhile: {} warn, {} error line(s){}\n\n", logs.warn, logs.error,
               logs.first.empty() ? "" : "; first: " + logs.first);
    std::fflush(stdout);
    return r;
  }

 private:
  // Writes made by a scenario, and how many of them failed.
  struct Writes {
    std::uint64_t written = 0, failed = 0;
  };

  // The scenario's name and first line.
  Result announce(Kind kind, int rate) const {
    Result r;
    r.kind = kind;
    r.rate = rate;
    switch (kind) {
      case Kind::kIdle:
        r.name = "idle (no load)";
        fmt::print("idle: no load for {} s ...\n", o_.idle_seconds);
        break;
      case Kind::kRequests:
        r.name = fmt::format("(a) requests {}/s", rate);
        fmt::print(
            "(a) explicit requests at {}/s for {} s: Get_Attribute_Single Identity instance 1 "
            "attribute 1,\n    nodes 1..{} in turn, one txid each, each unregistered once its "
            "reply is taken ...\n",
            rate, o_.seconds, kNodes);
        break;
      case Kind::kCommands:
        r.name = fmt::format("(b) commands {}/s", rate);
        fmt::print(
            "(b) PumpCommand writes at {}/s for {} s: round robin over the {} pumps, each pump's "
            "outputs\n    alternating (pump on, 1000 counts / pump off, 3000 counts) ...\n",
            rate, o_.seconds, kNodes);
        break;
      case Kind::kSameCommands:
        r.name = fmt::format("(b') same commands {}/s", rate);
        fmt::print(
            "(b') PumpCommand writes at {}/s for {} s: round robin over the {} pumps, each pump's "
            "outputs\n     always the same (pump on, 2000 counts) ...\n",
            rate, o_.seconds, kNodes);
        break;
    }
    std::fflush(stdout);
    return r;
  }

  // The scenario's load, for `seconds`.
  Writes write_load(Kind kind, int rate, double seconds) {
    Writes w;
    if (kind == Kind::kRequests) {
      w.written = paced(rate, seconds, [&](std::uint64_t i) {
        if (!load_.request(1 + static_cast<unsigned>(i % kNodes))) ++w.failed;
      });
    } else if (kind == Kind::kCommands) {
      w.written = paced(rate, seconds, [&](std::uint64_t i) {
        const unsigned mac = 1 + static_cast<unsigned>(i % kNodes);
        const bool on = (i / kNodes) % 2 == 0;
        if (!load_.command(mac, on, on ? 1000 : 3000)) ++w.failed;
      });
    } else if (kind == Kind::kSameCommands) {
      w.written = paced(rate, seconds, [&](std::uint64_t i) {
        if (!load_.command(1 + static_cast<unsigned>(i % kNodes), true, 2000)) ++w.failed;
      });
    } else {
      sleep_until_monotonic(monotonic_ns() + static_cast<std::int64_t>(seconds * 1e9));
    }
    return w;
  }

  // The requests' replies, waited for.
  void report_requests(std::uint32_t first_txid, std::uint64_t failed, Result& r) {
    const std::uint32_t last_txid = load_.next_txid();
    load_.wait_answered(first_txid, last_txid,
                        monotonic_ns() + static_cast<std::int64_t>(o_.reply_wait_seconds * 1e9));
    auto rep = load_.replies(first_txid, last_txid);
    r.sent = rep.sent;
    r.answered = rep.answered;
    r.device_success = rep.device_success;
    r.reply = summarize(std::move(rep.latency_us));
    fmt::print(
        "    requests sent {} ({:.1f}/s; {} writes failed), answered {} ({:.2f} %; waited at "
        "most {} s after the last)\n",
        rep.sent, static_cast<double>(rep.sent) / r.wall_s, failed, rep.answered,
        rep.sent ? 100.0 * static_cast<double>(rep.answered) / static_cast<double>(rep.sent) : 0.0,
        o_.reply_wait_seconds);
    fmt::print("      by status:");
    for (const auto& [status, n] : rep.by_status) fmt::print(" [{}] {}", status, n);
    fmt::print("; of status 1, CIP success: {}\n", rep.device_success);
    fmt::print("    reply latency, written -> reply taken: p50 {}  p99 {}  max {}\n",
               duration_text(r.reply.p50), duration_text(r.reply.p99), duration_text(r.reply.max));
  }

  // NodeStatus counters: rates per node over the samples of the window.
  static void report_node_counters(const Observed& seen, Result& r) {
    double polls_sum = 0, polls_min = 1e18, polls_max = 0, idle_sum = 0, responses_sum = 0;
    double accepted = 0, refused = 0, explicit_requests = 0, timeouts = 0;
    unsigned nodes = 0;
    for (unsigned mac = 1; mac <= kNodes; ++mac) {
      const auto& a = seen.first_counters[mac];
      const auto& b = seen.last_counters[mac];
      if (!a || !b || b->at <= a->at) continue;
      const double dt = static_cast<double>(b->at - a->at) / 1e9;
      const double polls = static_cast<double>(b->c.polls - a->c.polls) / dt;
      polls_sum += polls;
      polls_min = std::min(polls_min, polls);
      polls_max = std::max(polls_max, polls);
      idle_sum += static_cast<double>(b->c.idle_polls - a->c.idle_polls) / dt;
      responses_sum += static_cast<double>(b->c.poll_responses - a->c.poll_responses) / dt;
      accepted += static_cast<double>(b->c.commands_accepted - a->c.commands_accepted) / dt;
      refused += static_cast<double>(b->c.commands_refused - a->c.commands_refused);
      explicit_requests +=
          static_cast<double>(b->c.explicit_requests - a->c.explicit_requests) / dt;
      timeouts += static_cast<double>(b->c.poll_timeouts - a->c.poll_timeouts);
      ++nodes;
    }
    if (nodes > 0) {
      r.polls_per_node = polls_sum / nodes;
      fmt::print(
          "    polls per node per second (NodeStatus counters, {} nodes): mean {:.1f} (min {:.1f}, "
          "max {:.1f}; idle polls {:.1f}, responses {:.1f});\n      all nodes: poll timeouts "
          "{:.0f}, explicit requests sent {:.1f}/s (the bridge's own included), commands accepted "
          "{:.1f}/s, refused {:.0f}\n",
          nodes, r.polls_per_node, polls_min, polls_max, idle_sum / nodes, responses_sum / nodes,
          timeouts, explicit_requests, accepted, refused);
    } else {
      fmt::print(
          "    polls per node per second: no two NodeStatus samples of a node in the window\n");
    }
  }

  // The last PortStatus, and the PumpStates' freshness and gaps.
  static void report_states(const Observed& seen, Result& r) {
    if (seen.port) {
      fmt::print(
          "    port A (last PortStatus): {:.0f} frames/s, bus load {:.1f} %, scan cycle {:.1f} "
          "ms\n",
          seen.port->frames_per_second, seen.port->bus_load_percent, seen.port->scan_cycle_ms);
    }
    r.freshness = summarize(seen.freshness_us);
    unsigned gap_mac = 0;
    for (unsigned mac = 1; mac <= kNodes; ++mac) {
      if (seen.max_gap_us[mac] > r.max_gap_us) {
        r.max_gap_us = seen.max_gap_us[mac];
        gap_mac = mac;
      }
    }
    fmt::print(
        "    PumpState: {} samples taken ({:.1f}/s); freshness, take - source time:\n"
        "      p50 {}  p99 {}  max {}; longest gap between two samples of a pump {} (MAC {})\n",
        seen.pump_samples, static_cast<double>(seen.pump_samples) / r.wall_s,
        duration_text(r.freshness.p50), duration_text(r.freshness.p99),
        duration_text(r.freshness.max), duration_text(r.max_gap_us), gap_mac);
  }

  // The bridge's CPU time and RSS over the window, and by thread.
  static void report_cpu(Kind kind, const ProcessSample& before, const ProcessSample& after,
                         const Writes& writes, const Result& r) {
    const double cpu_s = ticks_seconds(after.ticks - before.ticks);
    fmt::print(
        "    bridge CPU: {:.1f} % of one core ({:.2f} s of utime + stime over {:.1f} s); RSS "
        "{} kB before, {} kB after ({:+} kB)\n",
        r.cpu_percent, cpu_s, r.wall_s, r.rss_before, r.rss_after,
        static_cast<std::int64_t>(r.rss_after) - static_cast<std::int64_t>(r.rss_before));
    if ((kind == Kind::kCommands || kind == Kind::kSameCommands) &&
        writes.written > writes.failed) {
      fmt::print("      = {:.1f} us of bridge CPU per command written\n",
                 cpu_s * 1e6 / static_cast<double>(writes.written - writes.failed));
    }
    print_threads(before, after, r.wall_s);
  }

  const Options& o_;
  BridgeProcess& bridge_;
  Load& load_;
  std::streamoff log_offset_ = 0;
};

int run(const Options& o) {
  const auto run_from = monotonic_ns();
  if (!std::filesystem::exists(o.dnbridge)) {
    throw std::runtime_error(o.dnbridge + " not found (build the dnbridge target, or --dnbridge)");
  }
  const int domain = o.domain >= 0 ? o.domain : 150 + static_cast<int>(getpid() % 40);
  const std::string tag = fmt::format("dnbridge-load-bench-{}", getpid());
  // For this process and, inherited, for the bridge.
  setenv("CYCLONEDDS_URI", dds::loopback_config(tag).c_str(), 1);
  char dir_template[] = "/tmp/dnbridge-load-bench-XXXXXX";
  if (!mkdtemp(dir_template)) throw std::runtime_error("mkdtemp failed");
  const std::filesystem::path dir = dir_template;

  print_run_header("dnbridge load benchmark", domain, tag);
  char host[256] = {};
  gethostname(host, sizeof host - 1);

  std::size_t max_requests = 16;
  for (int rate : o.request_rates) {
    max_requests += static_cast<std::size_t>(std::ceil(rate * o.seconds)) + 16;
  }

  BridgeProcess bridge(o.dnbridge, default_config_on_domain(o.dnbridge, domain), dir, "sim-rack",
                       o.bridge_cpu);
  const auto clock_offset_at_start = realtime_ns() - monotonic_ns();
  fmt::print(
      "bridge: {} --config {} (PID {}): the embedded default\n        (dnbridge "
      "--print-default-config) on domain {}; its log: {}\n",
      o.dnbridge, bridge.config_path().string(), bridge.pid(), domain, bridge.log_path().string());
  if (o.bridge_cpu >= 0 || o.load_cpu >= 0) {
    fmt::print("CPUs: the bridge on {}, this process on {}\n",
               o.bridge_cpu >= 0 ? fmt::format("CPU {}", o.bridge_cpu) : "any",
               o.load_cpu >= 0 ? fmt::format("CPU {}", o.load_cpu) : "any");
  } else {
    fmt::print("CPUs: every process and thread where the kernel puts it\n");
  }
  if (!pin_to_cpu(o.load_cpu)) {
    throw std::runtime_error(fmt::format("cannot keep this process on CPU {}", o.load_cpu));
  }

  Load load(domain, fmt::format("dnbridge-load-bench@{}:{}", host, getpid()), max_requests);
  const auto ready_from = monotonic_ns();
  if (!load.wait_ready(ready_from + 90'000'000'000, [&] { return !bridge.ended(); })) {
    throw std::runtime_error(fmt::format("the bridge did not become ready within 90 s ({}){}",
                                         load.readiness(),
                                         bridge.ended() ? "; it ended: " + *bridge.ended() : ""));
  }
  fmt::print(
      "ready after {:.1f} s: every node online with its inputs, the bridge's readers and reply "
      "writer matched\n\n",
      static_cast<double>(monotonic_ns() - ready_from) / 1e9);
  std::fflush(stdout);

  Runner runner(o, bridge, load);
  std::vector<Result> results;
  if (o.idle_seconds > 0) results.push_back(runner.run(Kind::kIdle, 0));
  for (int rate : o.request_rates) {
    if (rate > 0) results.push_back(runner.run(Kind::kRequests, rate));
  }
  for (int rate : o.command_rates) {
    if (rate > 0) results.push_back(runner.run(Kind::kCommands, rate));
  }
  for (int rate : o.same_command_rates) {
    if (rate > 0) results.push_back(runner.run(Kind::kSameCommands, rate));
  }
  const auto drift_us =
      static_cast<double>((realtime_ns() - monotonic_ns()) - clock_offset_at_start) / 1e3;

  const std::string ended = bridge.stop(10'000);
  load.stop();

  fmt::print("summary ({} s per scenario, idle {} s)\n", o.seconds, o.idle_seconds);
  fmt::print("  {:<26} {:>9} {:>13} {:>21} {:>11} {:>21} {:>9} {:>15}\n", "scenario", "CPU",
             "answered", "reply p50 / p99", "polls/node", "PumpState age p50/p99", "max gap",
             "RSS kB");
  for (const auto& r : results) {
    const std::string answered =
        r.kind == Kind::kRequests ? fmt::format("{}/{}", r.answered, r.sent) : "";
    const std::string reply =
        r.kind == Kind::kRequests
            ? fmt::format("{} / {}", duration_text(r.reply.p50), duration_text(r.reply.p99))
            : "";
    fmt::print(
        "  {:<26} {:>7.1f} % {:>13} {:>21} {:>9.1f}/s {:>21} {:>9} {:>15}\n", r.name, r.cpu_percent,
        answered, reply, r.polls_per_node,
        fmt::format("{} / {}", duration_text(r.freshness.p50), duration_text(r.freshness.p99)),
        duration_text(r.max_gap_us), fmt::format("{} -> {}", r.rss_before, r.rss_after));
  }
  fmt::print("targets:\n");
  for (const auto& r : results) {
    if (r.kind == Kind::kCommands && r.rate == 10000) {
      fmt::print(
          "  10 kHz PumpCommand flood costs the bridge <= {:.0f} % of one core: {:.1f} %: {}\n",
          o.command_target_percent, r.cpu_percent,
          verdict(r.cpu_percent <= o.command_target_percent));
    }
    if (r.kind == Kind::kRequests && r.rate == 1000) {
      fmt::print(
          "  every request answered at 1000/s: {}/{} answered, {} by the device (status 1, CIP "
          "success): {}\n",
          r.answered, r.sent, r.device_success,
          verdict(r.sent > 0 && r.answered == r.sent && r.device_success == r.sent));
    }
  }
  fmt::print(
      "wall clock moved {:+.1f} us against CLOCK_MONOTONIC since the bridge started (an "
      "error of at most that in PumpState ages)\n",
      drift_us);
  fmt::print("bridge stopped with SIGTERM: {}\n", ended);
  fmt::print("load average at end: {}; the run took {:.0f} s\n", load_average(),
             static_cast<double>(monotonic_ns() - run_from) / 1e9);
  if (ended.rfind("exit 0", 0) != 0) {
    fmt::print(stderr, "dnbridge-load-bench: the bridge did not stop in order; its log: {}\n",
               bridge.log_path().string());
    return 1;
  }
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  return 0;
}

}  // namespace
}  // namespace dnbridge::bench

int main(int argc, char** argv) {
  using namespace dnbridge::bench;
  CLI::App app{
      "dnbridge-load-bench: the dnbridge executable (embedded default configuration, simulated "
      "rack)\nunder explicit requests and PumpCommand floods written through DDS"};
  Options o;
  app.add_option("--dnbridge", o.dnbridge, "the bridge executable")->capture_default_str();
  app.add_option("--seconds", o.seconds, "each loaded scenario")->capture_default_str();
  app.add_option("--idle-seconds", o.idle_seconds, "the idle baseline; 0 to skip")
      ->capture_default_str();
  app.add_option("--request-rates", o.request_rates, "explicit requests per second; 0 for none")
      ->capture_default_str()
      ->delimiter(',');
  app.add_option("--command-rates", o.command_rates, "PumpCommand writes per second; 0 for none")
      ->capture_default_str()
      ->delimiter(',');
  app.add_option("--same-command-rates", o.same_command_rates,
                 "PumpCommand writes per second that never change the outputs (default: none)")
      ->delimiter(',');
  app.add_option("--reply-wait-seconds", o.reply_wait_seconds,
                 "how long replies are waited for after a request scenario")
      ->capture_default_str();
  app.add_option("--domain", o.domain, "DDS domain (default: from the process id)");
  app.add_option("--bridge-cpu", o.bridge_cpu, "CPU of the bridge (default: any)");
  app.add_option("--load-cpu", o.load_cpu, "CPU of this process (default: any)");
  CLI11_PARSE(app, argc, argv);
  try {
    return run(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dnbridge-load-bench: %s\n", e.what());
    return 1;
  }
}
