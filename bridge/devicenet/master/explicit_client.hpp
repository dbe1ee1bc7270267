#pragma once
// The client side of one node's explicit messaging: a queue of requests, one
// transaction outstanding at a time, a per-transaction timeout, acknowledged
// fragmentation in both directions, and a result for every request.
//
// Requests go to the slave on Group 2 message 4 (the explicit connection) or,
// for Allocate/Release, message 6 (unconnected); every answer comes back on
// Group 2 message 3 from the slave.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "bridge/can/frame_sink.hpp"
#include "bridge/cip/general_status.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"
#include "bridge/devicenet/wire/fragmentation.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::devicenet {

// How one request ended. `error` is empty on success; Errc::kDeviceError
// carries the device's general/additional status; kTimeout, kAborted (a
// fragment never acknowledged), kNotConnected and kStopped (cancelled) are the
// others.
struct ExplicitResult {
  std::error_code error;
  std::uint8_t service = 0;  // the request's service
  cip::GeneralStatus general_status = cip::GeneralStatus::kSuccess;
  std::uint8_t additional_status = cip::kNoAdditionalCode;
  InlineBytes<kMaxExplicitMessage> data;  // response service data on success

  bool ok() const noexcept { return !error; }
};

struct ExplicitCounters {
  std::uint64_t requests = 0;
  std::uint64_t responses = 0;
  std::uint64_t timeouts = 0;
  std::uint64_t device_errors = 0;
  std::uint64_t fragment_aborts = 0;
  std::uint64_t unexpected_frames = 0;  // answers with no request, wrong XID or service
  std::uint64_t malformed_frames = 0;
  std::uint64_t responses_before_final_ack = 0;  // request fragments left unacknowledged
};

class ExplicitClient {
 public:
  using Tag = std::uint32_t;
  static constexpr std::size_t kQueueCapacity = 8;

  struct Config {
    // Wait for the response after the request (or its last fragment) went
    // out, restarted by every response fragment. Longer than the 1 s a slave
    // waits before resending an unacknowledged fragment.
    Duration response_timeout = milliseconds(2000);
    ExplicitFragmentSender::Config fragments{};
  };

  class Listener {
   public:
    virtual ~Listener() = default;
    // Called once per submitted request. May submit further requests.
    virtual void on_explicit_result(Tag tag, const ExplicitResult& result, TimePoint now) = 0;
  };

  ExplicitClient(MacId master, MacId slave, Config config, can::FrameSink& sink,
                 Listener& listener) noexcept;

  // The body format the slave returned in its Allocate response.
  void set_body_format(BodyFormat format) noexcept { format_ = format; }
  BodyFormat body_format() const noexcept { return format_; }

  // Queues a request; sends it at once when nothing is outstanding. Fails with
  // kBusy when the queue is full and kOutOfRange when the request does not fit
  // the body format or the message buffer; no result is delivered then.
  // `timeout` replaces the configured response timeout for this request.
  Status submit(Tag tag, const RequestMessage& request, bool unconnected, TimePoint now,
                std::optional<Duration> timeout = std::nullopt) noexcept;

  // A frame from the slave on Group 2 message 3.
  void on_frame(Bytes payload, TimePoint now) noexcept;
  // Call when now >= deadline().
  void on_timer(TimePoint now) noexcept;
  TimePoint deadline() const noexcept;

  // Ends every queued and outstanding request with `reason`.
  void cancel_all(Errc reason, TimePoint now) noexcept;

  bool idle() const noexcept { return !outstanding_ && count_ == 0; }
  // The response timeout a request gets unless it names its own.
  Duration response_timeout() const noexcept { return config_.response_timeout; }
  // For requests submitted from now on (a live change of the port's timings).
  void set_response_timeout(Duration timeout) noexcept { config_.response_timeout = timeout; }
  std::size_t queued() const noexcept { return count_ + (outstanding_ ? 1 : 0); }
  const ExplicitCounters& counters() const noexcept { return counters_; }

 private:
  struct Pending {
    Tag tag = 0;
    bool unconnected = false;
    std::uint8_t service = 0;
    Duration timeout{};
    InlineBytes<kMaxExplicitMessage> message;
  };

  void start_next(TimePoint now) noexcept;
  void send_message(TimePoint now) noexcept;
  void send_payload(std::uint32_t can_id, Bytes payload, TimePoint now) noexcept;
  void handle_response(Bytes message, TimePoint now) noexcept;
  void end_request_transfer(TimePoint now) noexcept;
  bool reack_final_fragment(Bytes payload, TimePoint now) noexcept;
  void finish(const ExplicitResult& result, TimePoint now) noexcept;
  void fail(Errc reason, TimePoint now) noexcept;
  std::uint32_t request_id(bool unconnected) const noexcept;

  MacId master_;
  MacId slave_;
  Config config_;
  can::FrameSink& sink_;
  Listener& listener_;
  BodyFormat format_ = BodyFormat::k8_8;

  std::array<Pending, kQueueCapacity> queue_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;

  Pending current_{};
  bool outstanding_ = false;
  bool xid_ = false;
  TimePoint response_deadline_ = kNever;
  ExplicitFragmentSender sender_;
  ExplicitReassembler reassembler_;
  // Header and fragment byte of the last fragment of the latest response
  // reassembled, and the ack sent for it (empty: none yet).
  std::array<std::uint8_t, 2> final_fragment_{};
  InlineBytes<3> final_ack_;
  ExplicitCounters counters_{};
  bool in_callback_ = false;
  bool cancelling_ = false;
};

}  // namespace dnbridge::devicenet
