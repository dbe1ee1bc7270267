// (1) and (2): the bridge's latency, on one port of CDN127s polled every
// 10 ms or 100 ms (the shipped default).
//
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
//       poll schedule at every phase. Commands that meet a poll in flight:
//       from its response to the new poll written. The others split: until
//       the port's thread woke for the command, and from there to the frame
//       written; the first again at the wake-up the bridge's listener asks
//       for (the end of its work on Cyclone's thread), which leaves the
//       hand-over to the port's thread alone.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

#include "bridge_bench.hpp"
#include "bridge_bench_bridge.hpp"

namespace dnbridge::bench {
namespace {

// What one run of the bridge under the client gave.
struct LatencyRun {
  ClientOutput out;
  Reference cyc;  // ddsperf's, beside it
  double drift_us = 0;
  std::vector<Bridge::Handed> handed;
  std::vector<OutputFrame> frames;
  std::vector<WrittenFrame> written;
};

// The bridge on one port, every poll response a new analog input, under the
// client's commands; ddsperf beside it.
LatencyRun run_bridge_under_commands(const Run& run, int poll_ms) {
  const Options& o = run.options;
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
  Bridge bridge(s, run.domain, run.log);
  const auto offset_before = realtime_ns() - monotonic_ns();
  bridge.start();
  auto args = client_args("latency", run.domain, s.ports, s.nodes, o.latency_seconds);
  args.push_back("--command-interval-us");
  args.push_back(std::to_string(o.command_interval_ms * 1000));
  DdsperfBeside ddsperf(run);
  LatencyRun r;
  r.out = read_client(
      spawn_child(args, true, run.cpus.peer), o.latency_seconds,
      [&] { ddsperf.start(o.latency_seconds); }, [] {});
  bridge.stop();
  const auto offset_after = realtime_ns() - monotonic_ns();
  r.drift_us = static_cast<double>(offset_after - offset_before) / 1e3;
  r.cyc = ddsperf.report();
  r.handed = bridge.handed_responses();
  r.frames = bridge.output_frames();
  r.written = bridge.written_frames();
  return r;
}

// (1) whole: its figures.
Summary report_state_latency(const LatencyRun& r, const std::optional<Summary>& state_alone) {
  const Summary state = summarize(r.out.state_us);
  fmt::print("(1) poll response received by the master -> PumpState taken by the subscriber\n");
  fmt::print("    samples {}  p50 {}  p99 {}  max {}  min {}\n", state.count, us(state.p50),
             us(state.p99), us(state.max), us(state.min));
  fmt::print(
      "    wall clock moved {:+.1f} us against CLOCK_MONOTONIC during the run (an error of "
      "at most that)\n",
      r.drift_us);
  fmt::print("    ratio to Cyclone one-way:  p50 {:.2f}  p99 {:.2f}   target p99 <= 1.5: {}\n",
             state.p50 / r.cyc.p50, state.p99 / r.cyc.p99, verdict(state.p99 <= 1.5 * r.cyc.p99));
  if (state_alone) {
    const double added = state.p99 - state_alone->p99;
    fmt::print(
        "    the bridge's own addition: p99 {} - (0c)'s p99 {} = {}   target <= 10 us: {}\n"
        "                               p50 {} - (0c)'s p50 {} = {}\n",
        us(state.p99), us(state_alone->p99), us(added), verdict(added <= 10.0), us(state.p50),
        us(state_alone->p50), us(state.p50 - state_alone->p50));
  }
  return state;
}

// (1) in two, sample by sample: the response's way to the port's thread
// (the CAN controller waking it: here the simulated bus's thread, for a
// SocketCAN socket the kernel), and from there to the take (the bridge's
// own work, then Cyclone's, as in (0c), whose writer is awake when it stamps).
// Only responses that found the port's thread waiting, and were the
// first frame it was handed: for the others the time to the thread
// includes its own work. (A value a node's input took twice, its ramp
// having wrapped, matches no sample.)
void report_state_latency_split(const LatencyRun& r, std::size_t samples,
                                const std::optional<Summary>& state_alone) {
  constexpr std::int64_t kNotMatched = -1;
  std::map<std::pair<std::size_t, unsigned>, std::int64_t> wake_ns;
  for (const auto& h : r.handed) {
    const auto [it, added] = wake_ns.try_emplace({h.key, h.value}, h.slept ? h.ns : kNotMatched);
    if (!added) it->second = kNotMatched;
  }
  std::vector<double> wake_us, after_wake_us;
  for (const auto& st : r.out.states) {
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
      after_wake.count, samples, us(wake.p50), us(wake.p99), us(wake.max), us(after_wake.p50),
      us(after_wake.p99), us(after_wake.max));
  if (state_alone) {
    fmt::print("    the bridge's own addition after the wake-up, against (0c): p50 {}  p99 {}\n",
               us(after_wake.p50 - state_alone->p50), us(after_wake.p99 - state_alone->p99));
  }
}

// (2)'s commands matched to their poll frames, in parts (us).
struct CommandTimes {
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
};

// A command that met no poll in flight, in two: until the port's thread woke
// for it, and its own work from there. Only when the thread was waiting when
// the command was written and woke after: it may still have woken for
// something else (a poll due, a response) before the command reached it.
void split_free_command(const ClientOutput::Cmd& c, const WrittenFrame& wr, CommandTimes& t) {
  if (wr.waited_since <= c.at && wr.woke >= c.at) {
    t.to_woken.push_back(static_cast<double>(wr.woke - c.at) / 1e3);
    t.woken_to_write.push_back(static_cast<double>(wr.at - wr.woke) / 1e3);
    if (wr.woken_by >= c.at) {
      t.to_wake_call.push_back(static_cast<double>(wr.woken_by - c.at) / 1e3);
      t.wake_to_woken.push_back(static_cast<double>(wr.woke - wr.woken_by) / 1e3);
    }
  } else {
    ++t.not_split;
  }
}

CommandTimes match_commands(const LatencyRun& r) {
  std::map<std::pair<unsigned, unsigned>, OutputFrame> frames;
  for (const auto& f : r.frames) frames.emplace(std::make_pair(f.mac, f.value), f);
  std::map<std::pair<unsigned, unsigned>, WrittenFrame> written;
  for (const auto& f : r.written) written.emplace(std::make_pair(f.mac, f.value), f);
  CommandTimes t;
  for (const auto& c : r.out.commands) {
    auto it = frames.find({c.mac, c.value});
    auto wr = written.find({c.mac, c.value});
    if (it == frames.end() || wr == written.end()) continue;
    const double write_us = static_cast<double>(wr->second.at - c.at) / 1e3;
    t.to_write.push_back(write_us);
    t.frame_us = std::max(t.frame_us, static_cast<double>(it->second.end - it->second.start) / 1e3);
    if (wr->second.after_response) {
      ++t.waited;
      t.after_response_us.push_back(static_cast<double>(wr->second.at - wr->second.response_rx) /
                                    1e3);
    } else {
      t.to_write_free.push_back(write_us);
      split_free_command(c, wr->second, t);
    }
    t.to_start.push_back(static_cast<double>(it->second.start - c.at) / 1e3);
    t.to_end.push_back(static_cast<double>(it->second.end - c.at) / 1e3);
  }
  return t;
}

// (2)'s summaries: to the frame written (all, and with no poll in flight),
// to its start and to its end of frame.
struct CommandFigures {
  Summary write, write_free, start, end;
};

// (2) to the frame written and on the wire.
CommandFigures report_command_latency(const LatencyRun& r, const CommandTimes& t) {
  const CommandFigures f{summarize(t.to_write), summarize(t.to_write_free), summarize(t.to_start),
                         summarize(t.to_end)};
  fmt::print("(2) PumpCommand written -> poll frame with the new outputs\n");
  fmt::print("    commands written {}, their poll frames found {}\n", r.out.commands.size(),
             f.start.count);
  fmt::print("    to the frame written to the CAN interface:  p50 {}  p99 {}  max {}  min {}\n",
             us(f.write.p50), us(f.write.p99), us(f.write.max), us(f.write.min));
  fmt::print(
      "    {} of them ({:.1f} %) came while the node's previous poll was unanswered and\n"
      "    went out with its response (one poll at a time on a poll connection); the "
      "others:\n"
      "                                                p50 {}  p99 {}  max {}\n",
      t.waited, 100.0 * static_cast<double>(t.waited) / static_cast<double>(t.to_write.size()),
      us(f.write_free.p50), us(f.write_free.p99), us(f.write_free.max));
  if (!t.after_response_us.empty()) {
    // Such a command waits for the remaining transaction of the poll in
    // flight, then for the master to write the next poll: that last part
    // is to take no longer than one frame time.
    const Summary after = summarize(t.after_response_us);
    fmt::print(
        "    those {}: from the response of the poll in flight received to the new poll "
        "written\n"
        "                                                p50 {}  p99 {}  max {}\n"
        "      target p99 <= one frame time ({}, the poll frame at 500 kbit/s): {}\n",
        t.waited, us(after.p50), us(after.p99), us(after.max), us(t.frame_us),
        verdict(after.p99 <= t.frame_us));
  }
  fmt::print(
      "    to its start of frame on the bus:           p50 {}  p99 {}  max {}  min {}\n"
      "      (adds waiting for a frame already on the 500 kbit/s wire, and arbitration)\n",
      us(f.start.p50), us(f.start.p99), us(f.start.max), us(f.start.min));
  fmt::print("    to its end of frame:                        p50 {}  p99 {}\n", us(f.end.p50),
             us(f.end.p99));
  fmt::print(
      "    ratio to Cyclone one-way, written:          p50 {:.2f}  p99 {:.2f}   target p99 "
      "<= 1.5: {}\n",
      f.write.p50 / r.cyc.p50, f.write.p99 / r.cyc.p99, verdict(f.write.p99 <= 1.5 * r.cyc.p99));
  fmt::print("    ratio to Cyclone one-way, written, no poll in flight:  p50 {:.2f}  p99 {:.2f}\n",
             f.write_free.p50 / r.cyc.p50, f.write_free.p99 / r.cyc.p99);
  return f;
}

void report_command_addition(const Summary& write_free, const Summary& listener_alone) {
  const double added = write_free.p99 - listener_alone.p99;
  fmt::print(
      "    the bridge's own addition, no poll in flight: p99 {} - (0b) listener's p99 {} = {}"
      "   target <= 10 us: {}\n",
      us(write_free.p99), us(listener_alone.p99), us(added), verdict(added <= 10.0));
  fmt::print(
      "                                                 p50 {} - (0b) listener's p50 {} = {}\n",
      us(write_free.p50), us(listener_alone.p50), us(write_free.p50 - listener_alone.p50));
}

// (2) with no poll in flight, in two, and the first part in two again.
void report_command_latency_split(const CommandTimes& t,
                                  const std::optional<Summary>& listener_alone) {
  const Summary woken = summarize(t.to_woken);
  const Summary work = summarize(t.woken_to_write);
  fmt::print(
      "    no poll in flight, in two ({} commands written while the port's thread waited; {} "
      "others):\n"
      "      command written -> the port's thread woken for it:  p50 {}  p99 {}  max {}\n"
      "      the port's thread woken -> the frame written:       p50 {}  p99 {}  max {}\n",
      woken.count, t.not_split, us(woken.p50), us(woken.p99), us(woken.max), us(work.p50),
      us(work.p99), us(work.max));
  if (listener_alone) {
    fmt::print(
        "      the first against (0b) listener (Cyclone's delivery): p50 {}  p99 {} (the "
        "bridge's\n      listener taking the command to the port's inbox, and the "
        "hand-over to the port's thread)\n",
        us(woken.p50 - listener_alone->p50), us(woken.p99 - listener_alone->p99));
  }
  const Summary to_call = summarize(t.to_wake_call);
  const Summary handing = summarize(t.wake_to_woken);
  fmt::print(
      "      the first in two ({} of them: the thread woken by a wake() after the command):\n"
      "        command written -> the listener wakes the port's loop: p50 {}  p99 {}  max {}\n"
      "        that wake -> the port's thread running (the hand-over): p50 {}  p99 {}  max "
      "{}\n",
      to_call.count, us(to_call.p50), us(to_call.p99), us(to_call.max), us(handing.p50),
      us(handing.p99), us(handing.max));
  if (listener_alone) {
    fmt::print(
        "        the listener's part against (0b) listener: p50 {}  p99 {} (the bridge's "
        "listener\n        taking the command to the port's inbox)\n",
        us(to_call.p50 - listener_alone->p50), us(to_call.p99 - listener_alone->p99));
  }
}

}  // namespace

void measure_bridge_latency(const Run& run, int poll_ms, const std::optional<Summary>& state_alone,
                            const std::optional<Summary>& listener_alone) {
  const LatencyRun r = run_bridge_under_commands(run, poll_ms);
  const Summary state = report_state_latency(r, state_alone);
  report_state_latency_split(r, state.count, state_alone);
  const CommandTimes times = match_commands(r);
  const CommandFigures cmd = report_command_latency(r, times);
  if (listener_alone) report_command_addition(cmd.write_free, *listener_alone);
  report_command_latency_split(times, listener_alone);
  fmt::print(
      "    ratio to Cyclone one-way, start of frame:   p50 {:.2f}  p99 {:.2f}   target p99 "
      "<= 1.5: {}\n\n",
      cmd.start.p50 / r.cyc.p50, cmd.start.p99 / r.cyc.p99,
      verdict(cmd.start.p99 <= 1.5 * r.cyc.p99));
  std::fflush(stdout);
  if (state.count == 0 || cmd.start.count == 0) {
    throw std::runtime_error("no latency was measured");
  }
}

}  // namespace dnbridge::bench
