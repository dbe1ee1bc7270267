#pragma once
// The wire of a simulated Group 2 only DeviceNet slave of the predefined
// master/slave connection set: what every such device does with frames,
// whatever its objects. A device derives from it and answers the hooks
// below (Cdn127Slave, EdsSlave).
//
// Sans-IO: frames come in through on_frame(), time through on_timer() (call
// it when now >= next_deadline()), frames go out through the FrameSink given
// at construction. No threads, no clocks.
//
// Wire behaviour (bridge/PROTOCOL.md §1..§7): it listens to Group 2 messages
// 4 (explicit request), 5 (poll command), 6 (Allocate/Release) and 7
// (duplicate MAC check) for its MAC, and answers on Group 2 message 3
// (explicit and unconnected responses), Group 1 message 15 (poll response)
// and Group 2 message 7. Group 2 messages 1 and 2 for its MAC go to the
// device (on_io_message: a change-of-state acknowledgment), and so does
// message 0, the bit-strobe command, from the master that owns its
// connection set (its MAC is the master's); everything else (UCMM, Group
// 1/3) is ignored and counted.
// - Duplicate MAC ID check at power-up (§6); a duplicate is Communication
//   Fault.
// - The unconnected port (message 6) takes Allocate and Release of the
//   DeviceNet object only (0x02/0x03 otherwise, §3); its answers are never
//   fragmented.
// - The explicit connection reassembles fragmented requests and sends long
//   responses in acknowledged fragments (§5).
//
// In Communication Fault it listens to the Group 4 Offline Connection Set
// only (bridge/devicenet/wire/offline_connection.hpp has the layouts, their
// sources and what is assumed; OfflineOptions the choices):
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
//   would be (set_mac(); Rockwell 855T manual, "Off-Line Node Recovery");
//   the request is echoed with R/R set and the node restarts its duplicate
//   MAC check, also for an unchanged MAC: a MAC set offline, "possibly to the
//   same value", restarts the check (Dr. DeviceNet, can-wiki "Duplicate MAC
//   ID"). A refusal is not answered (no source gives an error form).
// Not done, for want of a source: other services (e.g. the baud change the
// ICP DAS manual mentions), staggered identify responses, ownership timeouts.
// Outside Communication Fault the set is ignored.
//
// Readings some field devices took (Group2Options):
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

#include "adapters/sim/generic/connection_set.hpp"
#include "adapters/sim/generic/delay_queue.hpp"
#include "adapters/sim/generic/group2_device.hpp"
#include "bridge/can/frame_sink.hpp"
#include "bridge/common/log.hpp"
#include "bridge/devicenet/wire/duplicate_mac.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"
#include "bridge/devicenet/wire/fragmentation.hpp"
#include "bridge/devicenet/wire/identifier.hpp"
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

// Responses a slow device may hold at once (Group2Options::*_response_delay):
// a master has one explicit request outstanding (and maybe an Allocate), and
// polls a few milliseconds apart at most.
inline constexpr std::size_t kMaxDelayedResponses = 8;
inline constexpr std::size_t kMaxDelayedPolls = 16;

struct Group2Options {
  // Who the device is on the duplicate MAC check and the offline set.
  std::uint16_t vendor_id = 0;
  std::uint32_t serial_number = 0;
  Duration duplicate_mac_window = seconds(1);
  Duration fragment_ack_timeout = seconds(1);
  OfflineOptions offline{};
  // A request in acknowledged fragments: every fragment is acked but the
  // last, which the response itself answers (sent at once, no ack before
  // it). Off: the last fragment is acked too, then the response follows
  // (bridge/PROTOCOL.md §5).
  bool no_ack_of_last_request_fragment = false;
  // A slow device: every explicit response (success or error, on the
  // explicit connection or the unconnected port) goes out this long after
  // its request arrived, and every poll response this long after its poll
  // command; in order. Fragment acks and the later fragments of a response
  // are not delayed. Zero: at once.
  Duration explicit_response_delay = Duration::zero();
  Duration poll_response_delay = Duration::zero();
};

class Group2Slave {
 public:
  enum class NetworkState : std::uint8_t {
    kOff,                // before power_on()
    kDuplicateMacCheck,  // silent except for the check
    kOnline,
    kCommunicationFault,  // duplicate MAC detected: silent until power cycled
  };

  Group2Slave(const Group2Slave&) = delete;
  Group2Slave& operator=(const Group2Slave&) = delete;
  virtual ~Group2Slave() = default;

  // First power-up (and power_cycle() for later ones): the device's volatile
  // state reset, the duplicate MAC check started.
  void power_on(TimePoint now) noexcept { start_up(now, PowerUpCause::kPowerOn); }
  void power_cycle(TimePoint now) noexcept { power_on(now); }

  void on_frame(const can::CanFrame& frame, TimePoint now) noexcept;
  void on_timer(TimePoint now) noexcept;
  TimePoint next_deadline() const noexcept;

  NetworkState network_state() const noexcept { return network_; }
  const SlaveCounters& counters() const noexcept { return counters_; }
  // The client MAC owning the offline connection set, if any.
  std::optional<devicenet::MacId> offline_owner() const noexcept {
    if (!offline_owner_.owned) return std::nullopt;
    return offline_owner_.client;
  }

 protected:
  Group2Slave(can::FrameSink& sink, Group2Options options, Logger log) noexcept;

  // --- the device behind the wire ---
  virtual devicenet::MacId device_mac() const noexcept = 0;
  virtual const ConnectionSet& connection_set() const noexcept = 0;
  virtual ConnectionSet& connection_set() noexcept = 0;
  // Power-up or restart: the device's volatile state, its MAC read.
  virtual void power_up_device(TimePoint now, PowerUpCause cause) noexcept = 0;
  // Time passing in every network state (a process behind the device), and
  // when it next needs it.
  virtual void advance_device(TimePoint now) noexcept = 0;
  virtual TimePoint process_deadline() const noexcept = 0;
  // Online: the device's timers, its connections' watchdogs among them.
  virtual void device_timer(TimePoint now) noexcept = 0;
  virtual TimePoint device_deadline() const noexcept = 0;
  // Runs an explicit request and writes the response message (service byte
  // first) into `out` (devicenet::kMaxExplicitMessage bytes); its size.
  virtual std::size_t execute(const devicenet::RequestMessage& request, std::uint8_t requester,
                              TimePoint now, MutableBytes out) noexcept = 0;
  // What the request just executed left to do once answered.
  virtual PendingAction take_pending_action() noexcept = 0;
  virtual void restore_factory_defaults() noexcept = 0;
  virtual PollResult poll(Bytes command, TimePoint now) noexcept = 0;
  // A duplicate MAC: connections dropped, outputs to their fault values.
  virtual void go_offline(TimePoint now) noexcept = 0;
  // The offline set's MAC change, as the DeviceNet object's attribute 1.
  virtual Reply set_mac(std::uint8_t mac) noexcept = 0;
  // Group 2 messages 1 and 2 for this node, and 0 from its master, online;
  // false: not taken (ignored and counted).
  virtual bool on_io_message(devicenet::Group2Message message, const can::CanFrame& frame,
                             TimePoint now) noexcept;

  // For what the device produces on its own (a change of state).
  void send(std::uint32_t id, Bytes payload, TimePoint now) noexcept;
  Logger& log() noexcept { return log_; }

 private:
  void start_up(TimePoint now, PowerUpCause cause) noexcept;
  void restart(TimePoint now) noexcept { start_up(now, PowerUpCause::kRestart); }
  void enter_communication_fault() noexcept;
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
  std::uint32_t response_id() const noexcept;
  devicenet::DuplicateMacCheck::Config duplicate_mac_config() const noexcept;

  can::FrameSink& sink_;
  Logger log_;
  Group2Options options_;
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
  // A response held back by Group2Options::explicit_response_delay, with
  // what its request left to do once it is sent.
  struct DelayedResponse {
    bool unconnected = false;
    std::uint8_t header = 0;
    InlineBytes<devicenet::kMaxExplicitMessage> message;  // service byte first
    PendingAction then = PendingAction::kNone;
  };
  DelayQueue<DelayedResponse, kMaxDelayedResponses> delayed_responses_;
  DelayQueue<InlineBytes<kMaxPollData>, kMaxDelayedPolls> delayed_polls_;
};

const char* to_string(Group2Slave::NetworkState s) noexcept;

}  // namespace dnbridge::sim
