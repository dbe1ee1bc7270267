#pragma once
// One scan-list node as the master drives it: its life cycle
//   absent -> allocate -> identify -> configure -> verify sizes -> online
// (with the faults wrong device, configuration fault and owned by another
// master), its poll connection and its explicit connection.
//
// Sans-IO: frames come in through on_*(), time through on_timer(now); frames
// go out through the FrameSink, events through the ScannerObserver.
#include <cstdint>
#include <optional>
#include <string>

#include "bridge/can/frame_sink.hpp"
#include "bridge/cip/objects.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/log.hpp"
#include "bridge/common/result.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/cos_consumer.hpp"
#include "bridge/devicenet/master/explicit_client.hpp"
#include "bridge/devicenet/master/input_link.hpp"
#include "bridge/devicenet/master/keep_alive.hpp"
#include "bridge/devicenet/master/node_state.hpp"
#include "bridge/devicenet/master/poll_connection.hpp"
#include "bridge/devicenet/master/release_sequence.hpp"
#include "bridge/devicenet/master/scan_list.hpp"
#include "bridge/devicenet/master/scanner_events.hpp"
#include "bridge/devicenet/wire/fragmentation.hpp"

namespace dnbridge::devicenet {

class Node final : private ExplicitClient::Listener,
                   private PollConnection::Listener,
                   private InputLink::Listener {
 public:
  // Largest poll message handled (fragmented I/O above 8 bytes).
  static constexpr std::size_t kMaxIoSize = kMaxIoMessageSize;
  // Internal request tags have this bit set; external request ids must not.
  static constexpr std::uint32_t kInternalTag = 0x8000'0000u;

  // `port`: the port's settings, read when they are used (live changes of
  // its timings reach the node; apply_port_timings() for the explicit
  // response timeout). The node keeps its own copy of `config`.
  Node(NodeConfig config, const ScannerConfig& port, can::FrameSink& sink,
       ScannerObserver& observer, Logger log);

  // Begins allocation at `first_attempt` (the scanner staggers nodes); the
  // state change is reported at `now`, when it happens.
  void start(TimePoint now, TimePoint first_attempt);
  // Orderly shutdown: an idle poll, then Release. stopped() tells when done.
  void begin_shutdown(TimePoint now);
  // Orderly shutdown of a node taken out of the scan list (or out to be
  // configured again): as begin_shutdown(), but its poll data is no longer
  // reported (the rack may already decode that MAC's data otherwise).
  // `why` ends the reasons of its last states ("taken out of the scan list").
  void retire(std::string why, TimePoint now);
  // A retired node whose connections went with the bus (suspend()): once
  // the master is back on the bus, a Release of both connections, which the
  // device may still hold, then stopped.
  void release_after_loss(TimePoint now);
  // The port's explicit response timeout changed: requests from now on use
  // it (unless the node has its own).
  void apply_port_timings();
  // Stops at once without sending anything (the port lost its MAC).
  void halt(std::string_view reason, TimePoint now);
  // Forgets its connections without sending anything and waits for start()
  // (the bus was lost; the master checks its MAC again first).
  void suspend(std::string_view reason, TimePoint now);

  void on_explicit_frame(Bytes payload, TimePoint now);   // Group 2 message 3
  void on_poll_response(Bytes payload, TimePoint now);    // Group 1 message 15
  void on_cos_message(Bytes payload, TimePoint now);      // Group 1 message 13
  void on_strobe_response(Bytes payload, TimePoint now);  // Group 1 message 14
  // The node sent a duplicate MAC check request: it is powering up.
  void on_duplicate_mac_request(TimePoint now);
  void on_timer(TimePoint now);
  TimePoint deadline() const;

  // New outputs (consumed-size bytes): sent on the next poll, or at once when
  // configured so. Clears idle. kOutOfRange when the size is wrong.
  Status set_outputs(Bytes data, TimePoint now);
  // Idle: zero-length polls, so the device applies its idle actions.
  void set_idle(bool idle, TimePoint now);
  // An explicit request from above; its result comes through the observer.
  Status request_explicit(std::uint32_t request_id, const RequestMessage& request, TimePoint now);

  // Poll slot: the node polls at phase + k * poll_period.
  void set_poll_phase(TimePoint phase) { poll_.set_phase(phase); }
  // The slot of the next poll; kNever when the node is not being polled.
  TimePoint next_poll() const;
  // Serves the next slot now, ahead of time (the scanner batches polls due
  // close together); the slot after it is the node's next. Nothing while a
  // poll is unanswered: the slot is then served at its time.
  void poll_ahead(TimePoint now);

  MacId mac() const { return config_.mac; }
  const NodeConfig& config() const { return config_; }
  NodeState state() const { return state_; }
  const std::string& reason() const { return reason_; }
  const NodeCounters& counters() const { return counters_; }
  const ExplicitCounters& explicit_counters() const { return client_.counters(); }
  const NodeError& last_error() const { return last_error_; }
  const NodeIdentity& identity() const { return identity_; }
  std::optional<std::uint8_t> device_state() const { return device_state_; }
  // The device's minor faults (Identity.Status), in words; empty when none.
  const std::string& minor_faults() const { return minor_faults_; }
  // What the device had for each of the profile's settings (index as in
  // NodeProfile::settings) when it was last read or read back; empty before
  // that. Complete once the node is online.
  const std::vector<std::vector<std::uint8_t>>& settings_in_force() const {
    return settings_in_force_;
  }
  bool idle() const { return poll_.idle(); }
  // Outputs and idle flag of the last poll the device answered.
  Bytes applied_outputs() const { return poll_.applied_outputs(); }
  bool applied_idle() const { return poll_.applied_idle(); }
  Duration poll_epr() const { return poll_.epr(); }
  // The wait for an explicit answer that requests from now on get.
  Duration explicit_response_timeout() const { return client_.response_timeout(); }
  Duration explicit_epr() const { return keep_alive_.epr(); }
  // The input connection's settings as the device gave them (EPR,
  // acknowledge timer, retry limit); empty without one.
  // A bit-strobe connection: the node answers the port's bit-strobe
  // commands (from the Set of its EPR on; the scanner sends them).
  bool strobed() const {
    return input_.consuming() && input_.configured()->strobed() && !shutting_down_;
  }
  std::optional<CosSettings> cos_settings() const { return input_.settings(); }
  bool stopped() const { return state_ == NodeState::kStopped; }
  // start() was called (a node never started holds no connection).
  bool started() const { return started_; }

 private:
  // The life-cycle steps, in start-up order; kStartup in node_lifecycle.cpp
  // says for each what it asks and where each answer leads.
  enum class Step : std::uint8_t {
    kNone,
    kAllocateExplicit,  // DeviceNet.Allocate(explicit)
    kReleaseStale,      // DeviceNet.Release(explicit) after "already allocated"
    kAllocationInfo,    // what the device has allocated besides
    kReleaseStalePoll,  // DeviceNet.Release(its I/O connections) left from before
    kVendor,
    kProductType,
    kProductCode,
    kRevision,
    kSerial,
    kName,
    kIdentityStatus,
    kIdentityState,
    kReadSetting,             // the profile's settings: Get,
    kWriteSetting,            // Set only where it differs,
    kReleasePollForSetting,   // (a device that refuses while a poll connection exists)
    kVerifySetting,           // Get again
    kCheckAttribute,          // the profile's checks: Get, compare
    kAllocatePoll,            // DeviceNet.Allocate(poll)
    kReleasePollForAllocate,  // DeviceNet.Release(poll) after "already allocated"
    kGetProducedPath,
    kSetProducedPath,
    kGetConsumedPath,
    kSetConsumedPath,
    kProducedSize,
    kConsumedSize,
    kFallbackProducedSize,
    kFallbackConsumedSize,
    kExplicitEpr,
    kPollEpr,
    // With an input connection (NodeProfile::input_connection): change of
    // state or cyclic (Connection 4), or bit-strobe (Connection 3; target_of()).
    kAllocateCos,            // DeviceNet.Allocate(change of state, cyclic or bit-strobe)
    kReleaseCosForAllocate,  // DeviceNet.Release(it) after "already allocated"
    kSetCosPath,             // its produced path, where the profile names one
    kCosInhibit,             // its production inhibit time (change of state, when configured)
    kCosSize,                // its produced size, checked
    kAckTimer,  // the Acknowledge Handler's timer and retry limit (acknowledged, not bit-strobe)
    kRetryLimit,
    kCosEpr,  // its EPR: the connection starts producing
    kOnline,  // not a request: the poll connection starts
    // Outside start-up.
    kKeepAlive,
    kReleaseFault,     // Release after a fault, then wait for the recheck
    kReleaseShutdown,  // Release at orderly shutdown
  };
  enum class Verb : std::uint8_t { kGet, kSet, kAllocate, kRelease };
  // What a refusal (a CIP error reply) of a step leads to.
  enum class OnRefusal : std::uint8_t {
    kFault,        // configuration fault naming object, attribute, status, expectation
    kWrongDevice,  // the identity the scan list expects cannot be read
    kGoOn,         // information only: the handler records it, then `next`
    kHandler,      // the step's handler decides (allocation, paths, sizes)
  };
  // What no answer (a timeout, an aborted or malformed reply) leads to.
  enum class OnSilence : std::uint8_t {
    kResend,   // sent again twice, then the node is lost
    kHandler,  // the handler decides (an absent node, a back-off)
  };
  // What a handler found, and so where the start-up goes.
  enum class Verdict : std::uint8_t {
    kNext,   // the row's `next`
    kAlt,    // the row's `alt`: the other way the answer may lead
    kAgain,  // this row once more, for the next setting or check
    kStop,   // the handler moved the node itself: a fault, a wait
  };
  // What a row's request takes from the node rather than from the row.
  struct Ask {
    InlineBytes<16> value;            // Set: the value
    std::uint8_t choice = 0;          // Allocate, Release: the row's unless changed
    std::optional<Duration> timeout;  // a bound on the wait for the answer
  };
  // One row of the start-up table: everything about a step. A step that
  // does not apply (`applies` false) is passed over to its `next`.
  struct StepRow {
    Step step{};
    NodeState phase{};  // the state reported while it runs
    Verb verb{};
    cip::AttributeRef target;  // Get/Set: the attribute; a profile's from the profile
    std::uint8_t choice = 0;   // Allocate/Release: allocation choice bits
    // Fills what the request takes from the node; and what sending it starts.
    void (Node::*ask)(Ask&, TimePoint) = nullptr;
    bool (Node::*applies)() const = nullptr;  // nullptr: always
    OnRefusal on_refusal = OnRefusal::kHandler;
    OnSilence on_silence = OnSilence::kResend;
    // Records what an answer says and judges it; nullptr: a good answer is
    // `next`.
    Verdict (Node::*handler)(const ExplicitResult&, TimePoint) = nullptr;
    Step next = Step::kNone;  // after a good answer, and where the row does not apply
    Step alt = Step::kNone;   // where Verdict::kAlt leads
  };
  static const StepRow kStartup[];
  static const StepRow& row(Step step);

  void on_explicit_result(std::uint32_t tag, const ExplicitResult& result, TimePoint now) override;
  void on_step_result(Step step, const ExplicitResult& result, TimePoint now);
  // The errors of an answer counted and kept as the node's last error.
  void record_answer(const ExplicitResult& result, TimePoint now);
  // What the answer to a row leads to: its handler's verdict, or the
  // row's own rule for a refusal.
  Verdict judge(const StepRow& rule, const ExplicitResult& r, TimePoint now);
  // Runs `step`, or the first row from it on that applies; kOnline starts
  // the poll connection.
  void enter(Step step, TimePoint now);
  // Sends a row's request, built from the row and its `ask`.
  void run(const StepRow& row, TimePoint now);
  // The attribute a step addresses (a profile's from the profile).
  cip::AttributeRef target_of(Step step) const;

  // The start-up table's handlers (kStartup, node_lifecycle.cpp): from the
  // allocation to the configuration in node_identify.cpp, the I/O
  // connections' in node_connections.cpp. Each records what the answer
  // says and returns where it leads as a Verdict.
  Verdict after_allocate_explicit(const ExplicitResult& r, TimePoint now);
  Verdict after_release_stale(const ExplicitResult& r, TimePoint now);
  Verdict after_allocation_info(const ExplicitResult& r, TimePoint now);
  Verdict after_identity_match(const ExplicitResult& r, TimePoint now);
  Verdict after_revision(const ExplicitResult& r, TimePoint now);
  Verdict after_serial(const ExplicitResult& r, TimePoint now);
  Verdict after_name(const ExplicitResult& r, TimePoint now);
  Verdict after_identity_status(const ExplicitResult& r, TimePoint now);
  Verdict after_identity_state(const ExplicitResult& r, TimePoint now);
  Verdict after_read_setting(const ExplicitResult& r, TimePoint now);
  Verdict after_write_setting(const ExplicitResult& r, TimePoint now);
  Verdict after_release_for_setting(const ExplicitResult& r, TimePoint now);
  Verdict after_verify_setting(const ExplicitResult& r, TimePoint now);
  Verdict after_check(const ExplicitResult& r, TimePoint now);
  Verdict after_allocate_poll(const ExplicitResult& r, TimePoint now);
  Verdict after_get_path(const ExplicitResult& r, TimePoint now);
  Verdict after_set_path(const ExplicitResult& r, TimePoint now);
  Verdict after_size(const ExplicitResult& r, TimePoint now);
  Verdict after_explicit_epr(const ExplicitResult& r, TimePoint now);
  Verdict after_poll_epr(const ExplicitResult& r, TimePoint now);
  Verdict after_allocate_cos(const ExplicitResult& r, TimePoint now);
  Verdict after_cos_path(const ExplicitResult& r, TimePoint now);
  Verdict after_cos_inhibit(const ExplicitResult& r, TimePoint now);
  Verdict after_cos_size(const ExplicitResult& r, TimePoint now);
  Verdict after_ack_setting(const ExplicitResult& r, TimePoint now);
  Verdict after_cos_epr(const ExplicitResult& r, TimePoint now);
  // A refused Allocate of an I/O connection (`what`): "already allocated"
  // released (Verdict::kAlt) and allocated once more; owned by another
  // master, or another refusal (with `needed_by` after the status), a fault.
  Verdict io_allocate_refused(const ExplicitResult& r, TimePoint now, std::string_view what,
                              std::string_view needed_by, IoAllocation& allocation);
  // The setting in hand done, with what the device has: the next one.
  void next_setting(Bytes in_force);

  // The rows' `ask`: what their requests take from the node.
  void ask_stale_io(Ask& ask, TimePoint now);
  void ask_setting(Ask& ask, TimePoint now);
  void ask_allocate_poll(Ask& ask, TimePoint now);
  void ask_produced_path(Ask& ask, TimePoint now);
  void ask_consumed_path(Ask& ask, TimePoint now);
  void ask_explicit_epr(Ask& ask, TimePoint now);
  void ask_poll_epr(Ask& ask, TimePoint now);
  void ask_allocate_cos(Ask& ask, TimePoint now);
  void ask_cos_release(Ask& ask, TimePoint now);
  void ask_cos_path(Ask& ask, TimePoint now);
  void ask_cos_inhibit(Ask& ask, TimePoint now);
  void ask_cos_epr(Ask& ask, TimePoint now);
  // The rows' `applies`: the optional steps, by what the profile asks for.
  bool has_setting() const;
  bool has_check() const;
  bool has_produced_path() const;
  bool has_consumed_path() const;
  bool has_input() const;
  bool has_input_path() const;
  bool has_input_inhibit() const;
  bool has_ack_handler() const;

  // A connection lost while the others live (the change-of-state
  // watchdog, bad poll responses): the outputs idle with one poll, every
  // connection released, then absent as after any loss.
  void lose_and_release(std::string reason, TimePoint now);
  void on_keepalive_result(const ExplicitResult& r, TimePoint now);
  // The answer to a Release after a fault or a loss, or at shutdown: the
  // next connection of the sequence, or the node left.
  void on_release_result(Step step, const ExplicitResult& r, TimePoint now);
  // The Identity Status and State read last: a major fault takes the node to
  // kDeviceFault (false); a minor one is warned of when it appears.
  bool check_health(TimePoint now);
  void note_minor_faults();
  void device_fault(std::string reason, TimePoint now);

  void issue(Step step, const RequestMessage& request, bool unconnected, TimePoint now,
             std::optional<Duration> timeout = std::nullopt);
  void resend_step(TimePoint now);
  void get(Step step, const cip::AttributeRef& target, TimePoint now);
  // The allocation choice of what the master holds (for Release).
  std::uint8_t held_connections() const;

  void attempt_allocate(TimePoint now);
  // A Release of `choice` (a new sequence, ReleaseSequence), or of the
  // next connection of the sequence in hand.
  void release(Step step, std::uint8_t choice, TimePoint now);
  void send_release(Step step, std::uint8_t choice, TimePoint now);
  // What a refused Get of the setting in hand was for, for the reason:
  // "; the configuration needs 03"; empty for other steps.
  std::string setting_expectation(Step step) const;
  // The path a step reads or writes, and the one the profile needs.
  bool path_step_produced(Step step) const;
  Bytes wanted_path(bool produced) const;
  Verdict check_sizes(TimePoint now);
  // "Connection 2 attribute 7", or the profile's fallback for the same size.
  std::string size_attribute(bool produced, bool fallback) const;
  void go_online(TimePoint now);
  void lose(std::string reason, TimePoint now);
  // Timers stopped, connections and requests dropped, nothing sent.
  void forget_connections(Errc why, TimePoint now);
  // A shutting-down node's poll was answered (well or badly) or timed out:
  // its idle poll next, or, that one done, the Release.
  void continue_shutdown(TimePoint now);
  void release_for_shutdown(TimePoint now);
  // Into a fault state, re-checked after fault_recheck; an online node's
  // outputs idle with one poll first, then what it holds is released.
  void enter_fault(NodeState fault, std::string reason, TimePoint now);
  void set_state(NodeState next, std::string reason, TimePoint now);
  void record(NodeError::Kind kind, TimePoint now, std::uint32_t got = 0,
              std::uint32_t expected = 0);
  void record_device_error(const ExplicitResult& result, TimePoint now);
  // Retry delay of the allocation and release paths: doubles up to the
  // port's maximum, with jitter, so that a broken node never floods the bus.
  Duration next_backoff();

  // The poll connection's answers (PollConnection::Listener); a bad one
  // also for a response while the node is not online.
  void on_poll_answer(Bytes inputs, bool late, TimePoint now) override;
  void on_bad_poll_answer(NodeError::Kind kind, std::uint32_t got, TimePoint now) override;
  // A poll for outputs that changed, if the node is online and polls on change.
  void poll_for_change(TimePoint now);
  void on_input_message(bool strobe_response, Bytes payload, TimePoint now);
  // The input connection's messages (InputLink::Listener); a bad one also
  // for a message the connection does not take (none, or of the other kind).
  void on_inputs(Bytes data, TimePoint now) override;
  void on_bad_inputs(NodeError::Kind kind, std::uint32_t got, TimePoint now) override;

  const NodeConfig config_;
  const ScannerConfig& port_;
  can::FrameSink& sink_;
  ScannerObserver& observer_;
  Logger log_;
  ExplicitClient client_;

  NodeState state_ = NodeState::kAbsent;
  std::string reason_ = "not started";
  Step step_ = Step::kNone;
  bool connected_ = false;  // the master holds the explicit connection
  bool shutting_down_ = false;
  bool started_ = false;
  bool reports_data_ = true;  // false once retired
  std::string shutdown_why_ = "orderly shutdown";
  TimePoint retry_at_ = kNever;
  Duration retry_delay_{};
  std::uint32_t jitter_state_ = 0;  // xorshift state, seeded from the MAC
  std::size_t setting_index_ = 0;
  std::vector<std::vector<std::uint8_t>> settings_in_force_;
  bool setting_retried_ = false;   // a refused Set retried once after releasing the poll
  std::size_t check_index_ = 0;    // the check in hand
  std::uint8_t stale_choice_ = 0;  // I/O connections left from before, to release
  ReleaseSequence releases_;
  InlineBytes<16> setting_found_;  // what the device had before the Set
  unsigned step_timeouts_ = 0;     // consecutive timeouts of the current life-cycle step
  Step last_step_ = Step::kNone;
  RequestMessage last_request_;
  InlineBytes<64> last_request_data_;
  bool last_unconnected_ = false;
  std::optional<Duration> last_timeout_;
  // The poll connection's paths as the device has them, and whether a Set of
  // them was refused: the sizes then decide whether what it has serves.
  InlineBytes<16> produced_path_in_force_;
  InlineBytes<16> consumed_path_in_force_;
  std::string path_refusal_;
  std::optional<std::uint32_t> produced_size_;
  std::optional<std::uint32_t> consumed_size_;
  // Where each size was read, and what the device answered where it was
  // asked first when it refused: both go into the reasons.
  bool produced_from_fallback_ = false;
  bool consumed_from_fallback_ = false;
  std::string size_refusal_;
  // The serial number first seen at this MAC (when none is pinned).
  std::optional<std::uint32_t> first_serial_;
  std::string minor_faults_;  // as last warned of
  bool epr_warned_ = false;

  NodeIdentity identity_;
  std::optional<std::uint8_t> device_state_;

  // The node's connections once the start-up has made them.
  NodeCounters counters_;
  PollConnection poll_;
  InputLink input_;
  KeepAlive keep_alive_;

  NodeError last_error_;
  RateLimitedLog error_log_limit_;
};

}  // namespace dnbridge::devicenet
