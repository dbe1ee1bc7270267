// Writes seed inputs for the scanner and cdn127_slave fuzz targets: the
// master (with the scanner target's scan list) and simulated CDN127s, with
// the example valve manifold bit-strobed at MAC 3, wired back to back with
// no bus delay, run on a fake clock. What the master
// receives, and when its timers run, is written as the scanner's input; what
// the CDN127 at MAC 1 receives, and its timers, as the slave's.
//
// Usage: fuzz_record_sessions <scanner corpus dir> <cdn127_slave corpus dir>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "adapters/sim/generic/eds_slave.hpp"
#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/profiles/eds/eds_file.hpp"
#include "tests/fuzz/support/session_records.hpp"

namespace {

using namespace dnbridge;
using fuzz::Op;

struct Queued {
  can::CanFrame frame;
  const void* from = nullptr;  // the sending side's sink
};

class QueueSink final : public can::FrameSink {
 public:
  explicit QueueSink(std::deque<Queued>& q) : q_(q) {}
  void send(const can::CanFrame& frame, TimePoint) override { q_.push_back({frame, this}); }

 private:
  std::deque<Queued>& q_;
};

// One side's record stream: records carry the time since the previous one.
class Stream {
 public:
  void add(Op op, TimePoint at, std::uint32_t id, Bytes data) {
    fuzz::append_record(bytes_, op, at - last_, id, data);
    last_ = at;
  }
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
  TimePoint last_ = fuzz::kSessionStart;
};

struct Scenario {
  std::string name;
  std::vector<bool> devices;  // a CDN127 at MAC 1, MAC 2, ... (the scan list: 1 and 2)
  bool stop_at_end = true;
  Duration length = seconds(6);
  bool scan_bus = false;  // a bus scan after the explicit request
  // After the explicit request, node 2 taken out of the scan list, then put
  // back with another poll period (a reload).
  bool toggle_node = false;
  bool valves = true;  // the valve manifold at MAC 3
};

profiles::eds::EdsFile valve_manifold() {
  std::ifstream in(std::string(DNBRIDGE_EDS_DIR) + "/dnbridge-example-valve-manifold.eds");
  std::stringstream text;
  text << in.rdbuf();
  auto parsed = profiles::eds::parse(text.str());
  if (!parsed.file) {
    std::fprintf(stderr, "the valve manifold's EDS does not read\n");
    std::exit(1);
  }
  return std::move(*parsed.file);
}

void write(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

void run(const Scenario& s, const std::string& scanner_dir, const std::string& slave_dir) {
  std::deque<Queued> queue;
  QueueSink master_sink(queue);
  devicenet::ScannerObserver observer;
  devicenet::Scanner scanner(fuzz::fuzz_scanner_config(), master_sink, observer, Logger());
  std::vector<std::unique_ptr<QueueSink>> slave_sinks;
  std::vector<std::unique_ptr<sim::Group2Slave>> slaves;
  for (std::size_t i = 0; i < s.devices.size(); ++i) {
    if (!s.devices[i]) continue;
    slave_sinks.push_back(std::make_unique<QueueSink>(queue));
    sim::SlaveOptions o =
        sim::default_slave_options(devicenet::MacId::from(static_cast<unsigned>(i + 1)).value());
    if (i == 0) o = fuzz::fuzz_slave_options();
    slaves.push_back(std::make_unique<sim::Cdn127Slave>(*slave_sinks.back(), o));
  }
  // The slave target's device is the one at MAC 1, when present.
  sim::Group2Slave* recorded = s.devices[0] ? slaves.front().get() : nullptr;
  if (s.valves) {
    slave_sinks.push_back(std::make_unique<QueueSink>(queue));
    sim::EdsSlaveOptions o;
    o.mac = fuzz::kFuzzStrobedMac;
    o.serial_number = 0xDB000103;
    slaves.push_back(std::make_unique<sim::EdsSlave>(*slave_sinks.back(), valve_manifold(), o));
  }

  Stream master_in, slave_in;
  TimePoint now = fuzz::kSessionStart;
  scanner.start(now);
  for (auto& d : slaves) d->power_on(now);
  const TimePoint end = now + s.length;
  bool outputs_set = false, request_sent = false, scan_started = false, stopped = false;
  int toggles = 0;

  const auto deliver = [&] {
    while (!queue.empty()) {
      const Queued q = queue.front();
      queue.pop_front();
      if (q.from == &master_sink) {
        for (auto& d : slaves) {
          if (d.get() == recorded) slave_in.add(Op::kFrame, now, q.frame.id, q.frame.payload());
          d->on_frame(q.frame, now);
        }
      } else {
        master_in.add(Op::kFrame, now, q.frame.id, q.frame.payload());
        scanner.on_frame(q.frame, now);
        // Other devices hear each other too (duplicate MAC checks); a
        // device never hears itself.
        for (std::size_t i = 0; i < slaves.size(); ++i) {
          if (slave_sinks[i].get() != q.from) slaves[i]->on_frame(q.frame, now);
        }
      }
    }
  };

  while (now < end || !stopped) {
    if (now >= end && !stopped) {
      if (s.stop_at_end) {
        master_in.add(Op::kStop, now, 0, {});
        scanner.stop(now);
      }
      stopped = true;
    }
    deliver();
    TimePoint next = scanner.next_deadline();
    for (auto& d : slaves) next = std::min(next, d->next_deadline());
    if (next > end + seconds(2)) break;
    now = std::max(now, next);
    if (scanner.next_deadline() <= now) {
      master_in.add(Op::kTimer, now, 0, {});
      scanner.on_timer(now);
    }
    for (auto& d : slaves) {
      if (d->next_deadline() <= now) {
        if (d.get() == recorded) slave_in.add(Op::kTimer, now, 0, {});
        d->on_timer(now);
      }
    }
    // Once the first node is online: new outputs, then a request from above.
    const devicenet::Node* n1 = scanner.node(devicenet::MacId::from(1).value());
    if (n1 && n1->state() == devicenet::NodeState::kOnline) {
      if (!outputs_set) {
        outputs_set = true;
        std::vector<std::uint8_t> d{0x00};  // node index 0
        d.resize(1 + n1->config().profile.consumed_size, 0);
        d[1] = 0x05;  // pump on, N2 ballast on
        master_in.add(Op::kSetOutputs, now, 0, Bytes(d));
        (void)scanner.set_outputs(n1->mac(), Bytes(d).subspan(1), now);
      } else if (!request_sent && now >= fuzz::kSessionStart + seconds(4)) {
        request_sent = true;
        // node 0; Get_Attribute_Single Identity 1 product name (7)
        const std::vector<std::uint8_t> d{0x00, 0x0E, 0x01, 0x01, 0x07};
        master_in.add(Op::kRequestExplicit, now, 0, Bytes(d));
        devicenet::RequestMessage m;
        m.service = 0x0E;
        m.class_id = 1;
        m.instance_id = 1;
        m.attribute = 7;
        (void)scanner.request_explicit(n1->mac(), m, now);
      } else if (s.scan_bus && request_sent && !scan_started &&
                 now >= fuzz::kSessionStart + seconds(5)) {
        scan_started = true;
        master_in.add(Op::kScanBus, now, 0, {});
        (void)scanner.scan_bus(now);
      } else if (s.toggle_node && request_sent && toggles < 2 &&
                 now >= fuzz::kSessionStart + seconds(5 + toggles)) {
        const devicenet::MacId two = devicenet::MacId::from(2).value();
        const std::vector<std::uint8_t> d{0x01, 0x01};  // node index 1; doubled period
        master_in.add(Op::kToggleNode, now, 0, Bytes(d));
        if (toggles++ == 0) {
          (void)scanner.remove_node(two, now);
        } else {
          auto again = fuzz::fuzz_scanner_config().nodes.at(1);
          again.poll_period *= 2;
          again.expected_packet_rate *= 2;
          (void)scanner.add_node(again, now);
        }
      }
    }
  }
  write(scanner_dir + "/session_" + s.name, master_in.bytes());
  if (recorded) write(slave_dir + "/session_" + s.name, slave_in.bytes());
  const auto state = [&](unsigned mac) {
    const devicenet::Node* n = scanner.node(devicenet::MacId::from(mac).value());
    return std::string(n ? devicenet::to_string(n->state()) : "not listed");
  };
  std::printf("%s: scanner %zu B, slave %zu B, node 1 %s, node 3 %s\n", s.name.c_str(),
              master_in.bytes().size(), slave_in.bytes().size(), state(1).c_str(),
              state(fuzz::kFuzzStrobedMac).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <scanner corpus dir> <cdn127_slave corpus dir>\n", argv[0]);
    return 2;
  }
  const std::vector<Scenario> scenarios = {
      {"both_online_then_stop", {true, true}, true, seconds(6)},
      {"one_absent", {true, false}, false, seconds(4)},
      {"startup_only", {true, true}, false, milliseconds(1500)},
      // A CDN127 at MAC 4, which the scan list does not have: found by the scan.
      {"bus_scan", {true, true, false, true}, true, seconds(15), true},
      // Node 2 out of the scan list (idle poll, Release), then back.
      {"reconfigure", {true, true}, true, seconds(10), false, true},
  };
  for (const auto& s : scenarios) run(s, argv[1], argv[2]);
  return 0;
}
