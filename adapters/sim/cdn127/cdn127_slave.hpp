#pragma once
// A simulated CDN127: a Group 2 only DeviceNet slave of the predefined
// master/slave connection set (explicit + poll), in front of a dry pump.
//
// Sans-IO: frames come in through on_frame(), time through on_timer() (call
// it when now >= next_deadline()), frames go out through the FrameSink given
// at construction. No threads, no clocks.
//
// Wire behaviour (bridge/PROTOCOL.md §1..§7, CDN127 manual "DeviceNet Message
// Types"): it listens to Group 2 messages 4 (explicit request), 5 (poll
// command), 6 (Allocate/Release) and 7 (duplicate MAC check) for its MAC, and
// answers on Group 2 message 3 (explicit and unconnected responses), Group 1
// message 15 (poll response) and Group 2 message 7. Everything else (UCMM,
// Group 1/3, bit strobe) is ignored and counted.
//
// In Communication Fault it listens to the Group 4 Offline Connection Set
// only (bridge/devicenet/wire/offline_connection.hpp has the layouts, their
// sources and what is assumed; SlaveOptions::offline the choices):
// - Offline Ownership Request (0x7EF): allocate 1 takes ownership for the
//   client MAC, 0 gives it up; answered on 0x7EE with the request echoed, R/R
//   set. A node owned by another client MAC stays silent. With
//   OwnershipIdentity::kTarget only the node named by vendor + serial answers.
// - Communication Faulted Request (0x7ED), identify service: answered on
//   0x7EC when it matches: the short forms by match/value (match 0: every
//   faulted node; match 1: the node whose MAC is value), the long form by
//   vendor + serial. The ICP DAS form's time delay byte offset is accepted
//   and not acted on: responses go out at once.
// - Communication Faulted Request, long form, set MAC service, naming this
//   node, while owned: the MAC is set as the DeviceNet object's attribute 1
//   would be (refused while the MAC switch is valid: manual, DeviceNet object;
//   also Rockwell 855T manual, "Off-Line Node Recovery"); the request is
//   echoed with R/R set and the node restarts its duplicate MAC check, also
//   for an unchanged MAC: a MAC set offline, "possibly to the same value",
//   restarts the check (Dr. DeviceNet, can-wiki "Duplicate MAC ID"). A refusal
//   is not answered (no source gives an error form).
// Not done, for want of a source: other services (e.g. the baud change the
// ICP DAS manual mentions), staggered identify responses, ownership timeouts.
// Outside Communication Fault the set is ignored.
//
// Readings of the manual some field devices took are options (SlaveOptions,
// each documented there); the two on the frame path are done here:
// - no_ack_of_last_request_fragment: the last fragment of a request is not
//   acked (nor a resend of it); the response answers it.
// - explicit_response_delay / poll_response_delay: responses wait in a
//   queue until due; next_deadline() includes them, on_timer() sends them.
//   What a request does (Allocate, Reset, ...) happens on arrival; a restart
//   that waits for its response (Identity Reset, a new MAC) comes after the
//   delayed response. A power cycle, restart or Communication Fault drops
//   what is still queued.
#include <cstddef>
#include <cstdint>
#include <optional>

#include "adapters/sim/cdn127/cdn127_device.hpp"
#include "adapters/sim/cdn127/cdn127_objects.hpp"
#include "adapters/sim/cdn127/delay_queue.hpp"
#include "adapters/sim/cdn127/pump_model.hpp"
#include "bridge/can/frame_sink.hpp"
#include "bridge/common/log.hpp"
#include "bridge/devicenet/wire/duplicate_mac.hpp"
#include "bridge/devicenet/wire/fragmentation.hpp"
#include "bridge/devicenet/wire/offline_connection.hpp"

namespace dnbridge::sim {

struct SlaveCounters {
  std::uint32_t frames_not_addressed = 0;  // other nodes' traffic
  std::uint32_t frames_ignored = 0;     // for us but dropped (unsupported, wrong state, malformed)
  std::uint32_t requests_refused = 0;   // answered with an error response
  std::uint32_t explicit_requests = 0;  // explicit requests executed (success or error)
  std::uint32_t polls_applied = 0;
  std::uint32_t polls_idle = 0;
  std::uint32_t polls_oversize = 0;  // longer than the consumed size: ignored
  std::uint32_t polls_invalid = 0;
  std::uint32_t polls_major_fault = 0;  // answered, outputs not applied: a major fault stands
  std::uint32_t polls_ignored = 0;      // no established poll connection
  std::uint32_t fragment_transfers_failed = 0;
  std::uint32_t restarts = 0;           // power-ups, Identity Reset, MAC change
  std::uint32_t offline_responses = 0;  // Group 4 responses sent
  std::uint32_t responses_dropped = 0;  // delayed responses not kept: the queue was full
};

// Responses a slow device may hold at once (SlaveOptions::*_response_delay):
// a master has one explicit request outstanding (and maybe an Allocate), and
// polls a few milliseconds apart at most.
inline constexpr std::size_t kMaxDelayedResponses = 8;
inline constexpr std::size_t kMaxDelayedPolls = 16;

class Cdn127Slave {
 public:
  enum class NetworkState : std::uint8_t {
    kOff,                // before power_on()
    kDuplicateMacCheck,  // silent except for the check
    kOnline,
    kCommunicationFault,  // duplicate MAC detected: silent until power cycled
  };

  Cdn127Slave(can::FrameSink& sink, SlaveOptions options = {}, Logger log = {});

  // First power-up (and power_cycle() for later ones): volatile state reset,
  // switches read, outputs off, the duplicate MAC check started. E2 persists.
  // Unrecoverable Identity faults end, recoverable ones stay (IdentityFaults);
  // a restart (Identity Reset, a new MAC) keeps both.
  void power_on(TimePoint now) noexcept;
  void power_cycle(TimePoint now) noexcept { power_on(now); }

  void on_frame(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_timer(TimePoint now) noexcept;
  TimePoint next_deadline() const noexcept;

  // --- observation and the test's hands on the device ---
  NetworkState network_state() const noexcept { return network_; }
  devicenet::MacId mac() const noexcept { return device_.mac(); }
  // 255 when no master owns the connection set.
  std::uint8_t owner() const noexcept { return device_.owner(); }
  ConnectionState explicit_state() const noexcept { return device_.explicit_connection().state; }
  ConnectionState poll_state() const noexcept { return device_.poll_connection().state; }
  const profiles::cdn127::PumpOutputs& outputs() const noexcept { return device_.pump().outputs(); }
  const SlaveCounters& counters() const noexcept { return counters_; }
  PumpModel& pump() noexcept { return device_.pump(); }
  const PumpModel& pump() const noexcept { return device_.pump(); }
  Cdn127Device& device() noexcept { return device_; }
  const Cdn127Device& device() const noexcept { return device_; }
  // The client MAC owning the offline connection set, if any.
  std::optional<devicenet::MacId> offline_owner() const noexcept {
    if (!offline_owner_.owned) return std::nullopt;
    return offline_owner_.client;
  }
  // Turns the front-panel switches; read at the next power-up.
  void set_switches(std::uint8_t mac_switch, std::uint8_t baud_switch) noexcept {
    device_.set_switches(mac_switch, baud_switch);
  }

 private:
  void send(std::uint32_t id, Bytes payload, TimePoint now) noexcept;
  void on_duplicate_mac(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_unconnected(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_explicit(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_poll(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_offline(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_offline_ownership(const devicenet::OfflineOwnershipMessage& m, TimePoint now) noexcept;
  void on_comm_faulted(const devicenet::CommFaultedMessage& m, TimePoint now) noexcept;
  bool names_this_node(std::uint16_t vendor_id, std::uint32_t serial_number) const noexcept;
  void handle_explicit_message(std::uint8_t header, Bytes message, TimePoint now) noexcept;
  // A response message (service byte first) to a request on the explicit
  // connection or the unconnected port: sent now, or queued for the delay.
  void respond(bool unconnected, std::uint8_t header, Bytes message, TimePoint now) noexcept;
  void transmit_response(bool unconnected, std::uint8_t header, Bytes message,
                         TimePoint now) noexcept;
  void send_explicit_response(std::uint8_t header, Bytes message, TimePoint now) noexcept;
  void send_poll_response(Bytes payload, TimePoint now) noexcept;
  // Sends the delayed responses due at `now`; false if one's restart took the node offline.
  bool send_due(TimePoint now) noexcept;
  void after_response(PendingAction action, TimePoint now) noexcept;
  void drop_delayed() noexcept;
  void restart(TimePoint now) noexcept;
  void start_up(TimePoint now, PowerUpCause cause) noexcept;
  void enter_communication_fault() noexcept;
  std::uint32_t response_id() const noexcept;

  can::FrameSink& sink_;
  Logger log_;
  Cdn127Device device_;
  devicenet::DuplicateMacCheck dup_check_;
  devicenet::ExplicitReassembler reassembler_;
  devicenet::ExplicitFragmentSender sender_;
  NetworkState network_ = NetworkState::kOff;
  SlaveCounters counters_;
  struct OfflineOwner {
    bool owned = false;
    devicenet::MacId client;
    std::uint16_t vendor_id = 0;
    std::uint32_t serial_number = 0;
  };
  OfflineOwner offline_owner_;
  // A response held back by SlaveOptions::explicit_response_delay, with
  // what its request left to do once it is sent.
  struct DelayedResponse {
    bool unconnected = false;
    std::uint8_t header = 0;
    InlineBytes<devicenet::kMaxExplicitMessage> message;  // service byte first
    PendingAction then = PendingAction::kNone;
  };
  DelayQueue<DelayedResponse, kMaxDelayedResponses> delayed_responses_;
  DelayQueue<InlineBytes<8>, kMaxDelayedPolls> delayed_polls_;
};

const char* to_string(Cdn127Slave::NetworkState s) noexcept;

}  // namespace dnbridge::sim
