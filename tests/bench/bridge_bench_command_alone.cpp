// (0b) Cyclone DDS alone on the path of a command: PumpCommands written by
// the commander process, taken here, nothing behind it, twice: on a waitset
// thread, and by a listener on Cyclone's thread (as the bridge takes them);
// one way, measured on CLOCK_MONOTONIC at both ends. The bridge's own
// addition to (2) is measured against the listener's.
#include <fmt/format.h>

#include <cstdio>
#include <map>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "adapters/dds/listener.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "bridge_bench.hpp"

namespace dnbridge::bench {
namespace {

// How the commands are taken.
enum class Taker {
  kWaitset,   // a waitset on a thread of its own
  kListener,  // a DATA_AVAILABLE listener, on Cyclone's delivering thread (as the bridge does)
};

// A reader of the run's PumpCommands in this process, with nothing behind
// it: each command's take time (CLOCK_MONOTONIC), by its MAC and analog
// output.
class CommandTaker {
 public:
  CommandTaker(int domain, Taker kind)
      : kind_(kind),
        participant_(static_cast<dds_domainid_t>(domain), "bench-direct"),
        topic_(participant_),
        // The listener's calls come on one Cyclone thread; detached (every
        // call over) before taken_at_ is read.
        listener_([this] { take(); }),
        stop_(participant_),
        waitset_(participant_) {
    const auto qos = dds::command_reader_qos(dds::rack_partitions(kRack));
    if (kind_ == Taker::kListener) {
      reader_.emplace(participant_, topic_, qos, listener_.get());
    } else {
      reader_.emplace(participant_, topic_, qos);
    }
    if (!reader_->set_status_mask(DDS_DATA_AVAILABLE_STATUS)) {
      (void)dds::DataListener::detach(*reader_);
      throw std::runtime_error("setting the reader's status mask failed");
    }
    if (kind_ == Taker::kWaitset) waitset_.attach(*reader_, 1);
    waitset_.attach(stop_, 2);
    thread_ = std::thread([this] { wait_and_take(); });
  }
  ~CommandTaker() { stop(); }
  CommandTaker(const CommandTaker&) = delete;
  CommandTaker& operator=(const CommandTaker&) = delete;

  // No take after this returns: taken_at() can be read.
  void stop() {
    if (!thread_.joinable()) return;
    (void)stop_.trigger();
    thread_.join();
    (void)dds::DataListener::detach(*reader_);
  }

  const std::map<std::pair<unsigned, unsigned>, std::int64_t>& taken_at() const {
    return taken_at_;
  }

 private:
  void take() {
    auto samples = reader_->take();
    const auto now = monotonic_ns();
    if (!samples) return;
    for (const auto& sample : *samples) {
      if (!sample.info().valid_data()) continue;
      taken_at_.emplace(
          std::make_pair(unsigned{sample.data().mac}, unsigned{sample.data().analog_output_raw}),
          now);
    }
  }

  void wait_and_take() {
    for (;;) {
      auto triggered = waitset_.wait(milliseconds(200));
      if (!triggered) continue;
      for (auto t : *triggered) {
        if (t == 2) return;
      }
      if (kind_ == Taker::kWaitset) take();
    }
  }

  const Taker kind_;
  std::map<std::pair<unsigned, unsigned>, std::int64_t> taken_at_;
  dds::Participant participant_;
  dds::Topic<dnbridge_PumpCommand> topic_;
  dds::DataListener listener_;
  std::optional<dds::Reader<dnbridge_PumpCommand>> reader_;
  dds::GuardCondition stop_;
  dds::WaitSet waitset_;
  std::thread thread_;
};

// Cyclone DDS alone on the path of a command: the commander process writes
// PumpCommands as in (2), at the same gaps, with the same QoS, and a reader
// in this process takes them (`kind`), with nothing behind it. Write
// (CLOCK_MONOTONIC in the commander) -> take (CLOCK_MONOTONIC here): one
// way, measured, not halved from a round trip.
std::vector<double> direct_oneway(const Run& run, Taker kind,
                                  const std::function<void()>& on_ready) {
  const Options& o = run.options;
  CommandTaker taker(run.domain, kind);
  auto args = client_args("oneway", run.domain, {"A"}, o.latency_nodes, o.direct_seconds);
  args.push_back("--command-interval-us");
  args.push_back(std::to_string(o.command_interval_ms * 1000));
  const ClientOutput out =
      read_client(spawn_child(args, true, run.cpus.peer), o.direct_seconds, on_ready, [] {});
  taker.stop();
  std::vector<double> us;
  for (const auto& c : out.commands) {
    auto it = taker.taken_at().find({c.mac, c.value});
    if (it != taker.taken_at().end()) us.push_back(static_cast<double>(it->second - c.at) / 1e3);
  }
  return us;
}

}  // namespace

std::optional<Summary> measure_command_path_alone(const Run& run) {
  const Options& o = run.options;
  std::optional<Summary> listener_figures;
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
    DdsperfBeside ddsperf(run);
    const Summary d =
        summarize(direct_oneway(run, taker, [&] { ddsperf.start(o.direct_seconds); }));
    const Reference ref = ddsperf.report();
    fmt::print("(0b) write -> take ({}), one way: samples {}  p50 {}  p99 {}  max {}\n",
               listener ? "listener" : "waitset", d.count, us(d.p50), us(d.p99), us(d.max));
    fmt::print("     ratio to ddsperf's one-way:  p50 {:.2f}  p99 {:.2f}\n\n", d.p50 / ref.p50,
               d.p99 / ref.p99);
    if (listener) listener_figures = d;
  }
  return listener_figures;
}

}  // namespace dnbridge::bench
