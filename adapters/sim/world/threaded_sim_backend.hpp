#pragma once
// The simulated bus as a port's CAN backend, with the simulated world on a
// thread of its own, as a real CAN controller and its devices are outside
// the bridge's process: the port thread only queues frames and is woken when
// frames arrive, the way it would be by a SocketCAN interface. The world's
// CPU time can then be told apart from the bridge's (sim_thread_cpu_time).
//
// A received frame is stamped with the time the world hands it over (never
// earlier than its simulated end of frame): what the master is given is the
// time the frame reached it, as a controller's receive timestamp would be.
// SimBackend, which runs the world on the port's thread, stays what the tests
// use.
#include <time.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "adapters/port/can_backend.hpp"
#include "adapters/sim/world/sim_slave.hpp"
#include "adapters/sim/world/sim_world.hpp"

namespace dnbridge::sim {

class ThreadedSimBackend final : public port::CanBackend {
 public:
  // A simulated bus at `bitrate` (0: ideal, see BusConfig) with a CDN127
  // at each of `device_macs`, powered on now; the world's thread starts here.
  ThreadedSimBackend(std::uint32_t bitrate, const std::vector<devicenet::MacId>& device_macs,
                     LogSink* log = nullptr);
  ~ThreadedSimBackend() override;
  ThreadedSimBackend(const ThreadedSimBackend&) = delete;
  ThreadedSimBackend& operator=(const ThreadedSimBackend&) = delete;

  can::FrameSink& sink() override { return sink_; }
  TimePoint now() const override;
  void wait(TimePoint deadline, port::FrameReceiver& receiver) override;
  void wake() override;
  port::BusCounters counters() const override;
  std::string interface_name() const override { return "simulated"; }
  std::uint32_t bitrate() const override { return bitrate_; }

  // Runs `fn` on the world's thread, between two runs of the world. Any thread.
  void post(std::function<void()> fn);
  // The simulated devices and the world: on the world's thread only (from a
  // posted function or a bus tap).
  SimWorld& world() { return world_; }
  SimSlave& device(devicenet::MacId mac);

  // CPU time the world's thread has used so far. Any thread.
  Duration sim_thread_cpu_time() const;

 private:
  // The master's side of the bus: what the port sends, queued for the world.
  class MasterSink final : public can::FrameSink {
   public:
    explicit MasterSink(ThreadedSimBackend& owner) : owner_(owner) {}
    void send(const can::CanFrame& frame, TimePoint now) override;

   private:
    ThreadedSimBackend& owner_;
  };
  // The master's node on the bus: what the world delivers to it.
  class MasterPort final : public BusPort {
   public:
    explicit MasterPort(ThreadedSimBackend& owner) : owner_(owner) {}
    void on_frame(const can::CanFrame& frame, TimePoint rx_time) override;

   private:
    ThreadedSimBackend& owner_;
  };

  void run();
  void hand_over();  // frames the world delivered to the master, to the port

  const std::uint32_t bitrate_;
  SimWorld world_;
  MasterSink sink_{*this};
  MasterPort master_port_{*this};
  NodeHandle handle_;
  std::map<unsigned, std::unique_ptr<SimSlave>> devices_;
  std::vector<std::pair<can::CanFrame, TimePoint>> delivered_;  // world's thread only

  // Port -> world.
  std::mutex world_mutex_;
  std::condition_variable world_woken_;
  std::vector<std::pair<can::CanFrame, TimePoint>> to_world_;
  std::vector<std::function<void()>> posted_;
  bool stop_ = false;

  // World -> port.
  std::mutex port_mutex_;
  std::condition_variable port_woken_;
  std::vector<std::pair<can::CanFrame, TimePoint>> to_port_;
  std::vector<std::pair<can::CanFrame, TimePoint>> receiving_;  // port thread only
  bool wake_ = false;

  std::atomic<std::uint64_t> frames_{0};
  std::atomic<std::uint64_t> bits_{0};

  std::thread thread_;
  clockid_t sim_clock_ = -1;  // the world's thread's CPU-time clock
};

}  // namespace dnbridge::sim
