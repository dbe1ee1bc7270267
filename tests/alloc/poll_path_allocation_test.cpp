// The poll path must not allocate: a scanner polling a rack for minutes
// should run from the memory it took at start-up. Every heap allocation made
// while the master handles a frame or a timer is counted here by replacing
// the global operator new; allocations by the simulated bus and devices are
// not the master's and are not counted.
#include <gtest/gtest.h>

#include <cstdlib>
#include <new>

#include "adapters/sim/world/sim_rack.hpp"
#include "adapters/sim/world/sim_world.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace {
thread_local bool t_counting = false;
thread_local std::size_t t_allocations = 0;
}  // namespace

void* operator new(std::size_t size) {
  if (t_counting) ++t_allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace dnbridge::test {
namespace {

using devicenet::MacId;

MacId mac(unsigned v) { return MacId::from(v).value(); }

// Counts while the master runs; not while the bus takes its frames.
class UncountedSink final : public can::FrameSink {
 public:
  explicit UncountedSink(can::FrameSink& inner) : inner_(inner) {}
  void send(const can::CanFrame& frame, TimePoint now) override {
    const bool was = t_counting;
    t_counting = false;
    inner_.send(frame, now);
    t_counting = was;
  }

 private:
  can::FrameSink& inner_;
};

class CountedMaster final : public sim::SimEndpoint {
 public:
  CountedMaster(sim::SimWorld& world, devicenet::ScannerConfig config,
                devicenet::ScannerObserver& observer)
      : handle_(world.bus().attach(*this)), sink_(world.bus().sink(handle_)) {
    scanner_.emplace(std::move(config), sink_, observer, Logger());
    world.add(*this);
  }
  devicenet::Scanner& scanner() { return *scanner_; }

  void on_frame(const can::CanFrame& frame, TimePoint rx) override {
    t_counting = true;
    scanner_->on_frame(frame, rx);
    t_counting = false;
  }
  TimePoint next_deadline() const override { return scanner_->next_deadline(); }
  void on_timer(TimePoint now) override {
    t_counting = true;
    scanner_->on_timer(now);
    t_counting = false;
  }

 private:
  sim::NodeHandle handle_;
  UncountedSink sink_;
  std::optional<devicenet::Scanner> scanner_;
};

TEST(PollPath, NoHeapAllocationOncePollingAndCommanding) {
  std::vector<rack::PumpConfig> pumps;
  for (unsigned m = 1; m <= 16; ++m) {
    rack::PumpConfig p;
    p.node.mac = mac(m);
    p.node.name = "pump";
    p.node.poll_period = milliseconds(10);
    p.node.expected_packet_rate = milliseconds(100);
    p.io = profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn127);
    pumps.push_back(p);
  }
  devicenet::ScannerConfig port;
  port.master_mac = mac(0);

  sim::SimWorld world(sim::BusConfig{can::kBitrate500k});
  rack::PumpRack rack(pumps);
  CountedMaster master(world, rack::PumpRack::scanner_config(port, pumps), rack);
  rack.attach(master.scanner());
  std::vector<std::unique_ptr<sim::SimSlave>> devices;
  for (const auto& p : pumps) {
    devices.push_back(std::make_unique<sim::SimSlave>(world, sim::default_slave_options(p.node.mac),
                                                      world.now()));
  }
  master.scanner().start(world.now());
  ASSERT_TRUE(world.run_until(
      [&] {
        return std::all_of(rack.pumps().begin(), rack.pumps().end(),
                           [](const auto& v) { return v.online; });
      },
      seconds(30)));
  // Past start-up: every node has sent its first keep-alive.
  world.run_for(seconds(3));

  t_allocations = 0;
  const auto responses_before = master.scanner().node(mac(5))->counters().responses;
  for (int second = 0; second < 10; ++second) {
    // Commands change every second, idle once in a while: the immediate-poll
    // and idle paths run too.
    for (const auto& p : pumps) {
      profiles::cdn127::PumpOutputs out;
      out.pump_on = second % 2 == 0;
      out.analog_out_raw = static_cast<std::uint16_t>(100 * second);
      t_counting = true;
      if (second == 7) {
        (void)rack.release_command(p.node.mac, world.now());
      } else {
        (void)rack.command(p.node.mac, out, world.now());
      }
      t_counting = false;
    }
    world.run_for(seconds(1));
  }
  const auto responses = master.scanner().node(mac(5))->counters().responses - responses_before;
  EXPECT_GT(responses, 900u);  // really polled: 10 s at 10 ms
  EXPECT_EQ(t_allocations, 0u) << "heap allocations on the poll path";
}

}  // namespace
}  // namespace dnbridge::test
