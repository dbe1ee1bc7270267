#pragma once
// What reaches the bridge from DDS: pump commands, explicit requests, bus
// scan requests and reload requests for this rack. A waitset on a thread of its own takes
// them and hands each to its port's loop through the loop's inbox; no DDS
// callback touches master state. Requests for other racks are left to their
// bridges.
#include <atomic>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "adapters/daemon/dds_publisher.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/port/port_loop.hpp"
#include "bridge/common/log.hpp"

namespace dnbridge::daemon {

class DdsInput {
 public:
  // `reload`: called (on the input's thread) with each reload request for
  // this rack; it must return at once (Daemon::request_reload queues it).
  DdsInput(const dds::Participant& participant, DdsPublisher& publisher, std::string rack,
           std::map<std::string, port::PortLoop*, std::less<>> ports, Logger log,
           std::function<void(ReloadCall)> reload = {});
  ~DdsInput();
  DdsInput(const DdsInput&) = delete;
  DdsInput& operator=(const DdsInput&) = delete;

  void start();
  void stop();  // returns when the thread has ended

  // Samples with data for this rack taken so far (any thread).
  std::uint64_t commands_taken() const noexcept { return commands_taken_.load(); }
  std::uint64_t requests_taken() const noexcept { return requests_taken_.load(); }

 private:
  void run();
  void take_commands();
  bool take_requests();  // true when requests may remain
  void take_scan_requests();
  void on_scan_request(const dds::Sample<dnbridge_BusScanRequest>& sample);
  void take_reload_requests();
  void on_command(const dnbridge_PumpCommand& c, const dds::SampleInfo& info);
  void on_request(const dnbridge_ExplicitRequest& r, std::span<const unsigned char> serialized);
  void note_clock_skew(const dnbridge_PumpCommand& c, const dds::SampleInfo& info);
  port::PortLoop* port_of(std::string_view name);

  std::string rack_;
  DdsPublisher& publisher_;
  std::map<std::string, port::PortLoop*, std::less<>> ports_;
  Logger log_;
  // The rack's partition: DDS delivers this bridge its own rack's commands
  // and requests only (dds::rack_partition).
  std::vector<std::string> partition_;
  dds::Reader<dnbridge_PumpCommand> commands_;
  dds::Reader<dnbridge_ExplicitRequest> requests_;
  // Absent when DDS Security does not grant the service (unless_denied).
  std::optional<dds::Reader<dnbridge_BusScanRequest>> scan_requests_;
  std::optional<dds::Reader<dnbridge_ReloadRequest>> reload_requests_;
  std::function<void(ReloadCall)> reload_;
  dds::TakeBuffer<dnbridge_PumpCommand> command_buffer_;
  dds::TakeBuffer<dnbridge_ExplicitRequest> request_buffer_;
  std::vector<std::vector<unsigned char>> request_cdr_;
  dds::GuardCondition stop_;
  dds::WaitSet waitset_;
  std::thread thread_;
  RateLimitedLog warn_limit_;
  RateLimitedLog skew_limit_;
  std::atomic<std::uint64_t> commands_taken_{0};
  std::atomic<std::uint64_t> requests_taken_{0};
  std::uint64_t commands_stamped_ahead_ = 0;
  std::uint64_t requests_refused_for_names_ = 0;
  std::uint64_t requests_dropped_for_size_ = 0;
};

}  // namespace dnbridge::daemon
