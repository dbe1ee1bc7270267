#pragma once
// The simulated bus as a port's CAN backend: a SimWorld with a simulated
// CDN127 per pump and a device driven by its EDS per node of profile "eds",
// run in real time on the steady clock. The master is not a
// simulation endpoint here: its frames reach the world through sink(), and
// the world's frames reach it through wait(), exactly as with a real bus.
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "adapters/port/can_backend.hpp"
#include "adapters/sim/world/sim_eds_slave.hpp"
#include "adapters/sim/world/sim_slave.hpp"
#include "adapters/sim/world/sim_world.hpp"

namespace dnbridge::sim {

// A simulated device driven by its EDS file, at a MAC.
struct EdsDeviceSpec {
  devicenet::MacId mac;
  std::shared_ptr<const profiles::eds::EdsFile> eds;
};

class SimBackend final : public port::CanBackend, private BusPort {
 public:
  // A simulated bus at `bitrate` with a CDN127 at each of `device_macs` and
  // a device at each of `eds_devices`, powered on now.
  SimBackend(std::uint32_t bitrate, const std::vector<devicenet::MacId>& device_macs,
             LogSink* log = nullptr, const std::vector<EdsDeviceSpec>& eds_devices = {});
  ~SimBackend() override;

  can::FrameSink& sink() override { return sink_; }
  TimePoint now() const override;
  void wait(TimePoint deadline, port::FrameReceiver& receiver) override;
  void wake() override;
  port::BusCounters counters() const override;
  std::string interface_name() const override { return "simulated"; }
  std::uint32_t bitrate() const override { return world_.bus().bitrate(); }

  // The simulated devices, for tests and demonstrations (port thread only).
  SimWorld& world() { return world_; }
  SimSlave& device(devicenet::MacId mac);
  SimEdsSlave& eds_device(devicenet::MacId mac);

 private:
  // What the master sends: into the candump log, then onto the bus.
  class MasterSink final : public can::FrameSink {
   public:
    explicit MasterSink(SimBackend& owner) : owner_(owner) {}
    void send(const can::CanFrame& frame, TimePoint now) override;

   private:
    SimBackend& owner_;
  };

  void on_frame(const can::CanFrame& frame, TimePoint rx_time) override;

  SimWorld world_;
  NodeHandle handle_;
  MasterSink sink_{*this};
  std::map<unsigned, std::unique_ptr<SimSlave>> devices_;
  std::map<unsigned, std::unique_ptr<SimEdsSlave>> eds_devices_;
  std::deque<std::pair<can::CanFrame, TimePoint>> received_;

  std::mutex mutex_;
  std::condition_variable woken_;
  bool wake_ = false;
};

}  // namespace dnbridge::sim
