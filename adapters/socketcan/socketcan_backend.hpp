#pragma once
// A port's CAN backend on a SocketCAN interface (can0, vcan0, ...).
//
// One CAN_RAW socket, non-blocking, in an epoll set with a timerfd (the
// port's next deadline and this backend's own retries) and an eventfd (wake()
// from other threads). Everything but wake() runs on the port's thread.
//
// - Receive filters pass only what a master needs (master_filters()); error
//   frames are on and become the bus state, error counters and log events.
// - Every received frame carries the kernel's receive timestamp, moved onto
//   the monotonic clock of now(): it is the frame's time, and so the DDS
//   source time of what it causes.
// - Transmit back-pressure: when the socket's send buffer is full (EAGAIN)
//   frames wait in order in a bounded queue, sent again when epoll reports
//   the socket writable; when the interface's queue is full (ENOBUFS, which
//   epoll does not signal) they are retried on a timer that backs off. A
//   frame never overtakes an earlier one.
// - Interface absent or down at start, or no SocketCAN in the kernel: the
//   bus is reported down and the interface checked again periodically, as
//   below.
// - Interface down or removed (ENETDOWN, ENODEV): the socket is closed, the
//   bus reported down, and the interface checked again periodically; when it
//   is up again a new socket is opened and traffic resumes. The master's
//   nodes time out meanwhile and are allocated again by the master itself.
// - Bus-off: transmission stops and the policy decides who restarts the
//   controller (BusOffRecovery). Frames to send while the bus is off or the
//   interface down are dropped and counted, not kept: they would be stale.
#include <cstdio>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "adapters/port/can_backend.hpp"
#include "adapters/socketcan/can_io.hpp"
#include "adapters/socketcan/can_socket.hpp"
#include "adapters/socketcan/error_frame.hpp"
#include "bridge/common/log.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::socketcan {

enum class BusOffRecovery : std::uint8_t {
  kInterface,  // the interface restarts itself (ip link ... restart-ms N)
  kRestart,    // this backend restarts it (libsocketcan; needs CAP_NET_ADMIN)
  kReport,     // stays off and is reported until someone restarts it
};
const char* to_string(BusOffRecovery r) noexcept;

// The identifiers a DeviceNet master needs: Group 1 message 15 (poll
// responses), Group 2 messages 3 (explicit and unconnected responses) and 7
// (duplicate MAC ID checks, every MAC: a node's check says it powered up),
// and Group 4 (the offline connection set).
std::vector<CanFilter> master_filters();

struct SocketCanOptions {
  std::string interface;           // "can0"
  std::uint32_t bitrate = 500000;  // the bus's; compared with the interface's own
  std::vector<CanFilter> filters = master_filters();
  BusOffRecovery bus_off = BusOffRecovery::kInterface;
  Duration restart_delay = milliseconds(500);  // kRestart: bus-off to restart
  Duration reopen_period = milliseconds(500);  // checks of an interface that is down
  std::size_t transmit_queue_limit = 256;      // frames waiting for the interface
  int receive_buffer = 0;                      // SO_RCVBUF; 0: the system's
};

class SocketCanBackend final : public port::CanBackend {
 public:
  // Throws std::runtime_error when the interface exists but is not a CAN
  // interface (a configuration mistake). An interface that is absent or
  // down is not an error, nor is a kernel without SocketCAN (the module may
  // come later): the backend starts down, says why, and opens the interface
  // when it appears.
  SocketCanBackend(SocketCanOptions options, Logger log);
  // The same on `io`'s system calls and clock (tests inject faults there);
  // `io` outlives the backend.
  SocketCanBackend(SocketCanOptions options, Logger log, CanIo& io);
  ~SocketCanBackend() override;
  SocketCanBackend(const SocketCanBackend&) = delete;
  SocketCanBackend& operator=(const SocketCanBackend&) = delete;

  can::FrameSink& sink() override { return sink_; }
  TimePoint now() const override;
  void wait(TimePoint deadline, port::FrameReceiver& receiver) override;
  void wake() override;
  port::BusCounters counters() const override { return bus_; }
  std::string interface_name() const override { return options_.interface; }
  std::uint32_t bitrate() const override { return options_.bitrate; }
  std::string problem() const override { return problem_; }

  struct Stats {
    std::uint64_t received = 0;           // data frames handed to the master
    std::uint64_t transmitted = 0;        // frames the interface took
    std::uint64_t transmit_dropped = 0;   // given up: down, bus-off, queue full, refused
    std::uint64_t transmit_deferred = 0;  // waited in the queue at least once
    std::uint64_t receive_overruns = 0;   // dropped by the socket's receive queue
    std::uint64_t error_frames = 0;
    std::uint64_t foreign_frames = 0;  // extended or remote frames, ignored
    std::uint64_t reopens = 0;         // the interface came back
    std::uint64_t restarts = 0;        // bus-off restarts requested
  };
  const Stats& stats() const noexcept { return stats_; }
  std::size_t transmit_queued() const noexcept { return queue_.size(); }
  // When the next transmit retry after ENOBUFS is due (kNever: none).
  TimePoint transmit_retry_at() const noexcept { return transmit_retry_at_; }
  // When the next check of an interface that is down is due (kNever: none).
  TimePoint reopen_at() const noexcept { return reopen_at_; }
  // When the next bus-off restart is due (kNever: none).
  TimePoint restart_at() const noexcept { return restart_at_; }
  bool is_up() const noexcept { return socket_.is_open(); }

 private:
  class Sink final : public can::FrameSink {
   public:
    explicit Sink(SocketCanBackend& backend) : backend_(backend) {}
    void send(const can::CanFrame& frame, TimePoint now) override { backend_.transmit(frame, now); }

   private:
    SocketCanBackend& backend_;
  };

  void transmit(const can::CanFrame& frame, TimePoint now);
  // False when the frame could not go now and the queue must wait.
  bool try_write(const can::CanFrame& frame, TimePoint now);
  void enqueue(const can::CanFrame& frame, TimePoint now);
  void flush(TimePoint now);
  void drop_queue(const char* why);
  void want_writable(bool on);

  void try_open(TimePoint now);
  void go_down(const std::string& why, TimePoint now);
  // Every change of bus_.state after construction goes here: it counts the
  // losses.
  void set_bus_state(port::BusState state);
  void receive(port::FrameReceiver& receiver, bool& delivered, TimePoint now);
  void on_error_frame(const Received& r, TimePoint now);
  void run_timers(TimePoint now);
  TimePoint own_deadline() const;
  void arm_timer(TimePoint at);
  std::optional<port::BusState> state_from_netlink();

  SocketCanOptions options_;
  Logger log_;
  CanIo* io_;
  FileDescriptor epoll_;
  FileDescriptor wake_fd_;
  FileDescriptor timer_fd_;
  CanSocket socket_;
  Sink sink_{*this};

  port::BusCounters bus_;
  std::string problem_;
  Stats stats_;

  std::deque<can::CanFrame> queue_;
  bool writable_wanted_ = false;          // EPOLLOUT armed (EAGAIN)
  TimePoint transmit_retry_at_ = kNever;  // ENOBUFS
  Duration transmit_backoff_{};
  TimePoint reopen_at_ = kNever;
  TimePoint restart_at_ = kNever;
  TimePoint armed_ = kNever;
  std::uint32_t last_drops_ = 0;

  RateLimitedLog transmit_log_limit_;
  RateLimitedLog error_log_limit_;
};

}  // namespace dnbridge::socketcan
