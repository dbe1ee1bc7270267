#pragma once
// The predefined master/slave connection set of a simulated Group 2 only
// slave, as the DeviceNet and Connection objects see it: who owns it, which
// connections Allocate made (instance 1 explicit, 2 poll, 3 bit-strobe, 4
// change of state or cyclic), their states, expected packet rates, watchdogs and timeout
// actions (bridge/PROTOCOL.md §3, §7, §8). No frames and no data here: the
// device decides what its I/O connections carry and what its outputs do when
// one of them goes (ConnectionEvents).
#include <cstdint>

#include "bridge/cip/general_status.hpp"
#include "bridge/cip/objects.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::sim {

// Connection object attribute 1 (bridge/PROTOCOL.md §7).
enum class ConnectionState : std::uint8_t {
  kNonExistent = 0,
  kConfiguring = 1,
  kWaitingForConnectionId = 2,
  kEstablished = 3,
  kTimedOut = 4,
  kDeferredDelete = 5,
};

// Connection object attribute 12 (bridge/PROTOCOL.md §7).
enum class WatchdogAction : std::uint8_t {
  kTimedOut = 0,
  kAutoDelete = 1,
  kAutoReset = 2,
  kDeferredDelete = 3,
};

// The outcome of a service: CIP general status and additional code.
struct Reply {
  cip::GeneralStatus status = cip::GeneralStatus::kSuccess;
  std::uint8_t additional = cip::kNoAdditionalCode;

  bool ok() const noexcept { return status == cip::GeneralStatus::kSuccess; }
  friend bool operator==(const Reply&, const Reply&) = default;
};
inline constexpr Reply kReplyOk{};
constexpr Reply reply_error(cip::GeneralStatus s,
                            std::uint8_t additional = cip::kNoAdditionalCode) noexcept {
  return Reply{s, additional};
}

// Connection object instances of the predefined master/slave set (cip's).
namespace connection_instance {
using cip::connection_instance::kBitStrobe;
using cip::connection_instance::kChangeOfState;
using cip::connection_instance::kExplicit;
using cip::connection_instance::kPoll;
}  // namespace connection_instance

struct Connection {
  ConnectionState state = ConnectionState::kNonExistent;
  std::uint16_t expected_packet_rate_ms = 0;
  WatchdogAction watchdog_action = WatchdogAction::kTimedOut;
  // The assemblies the produced and consumed paths (attributes 14, 16) name;
  // I/O connections only, 0 for none.
  std::uint16_t produced_assembly = 0;
  std::uint16_t consumed_assembly = 0;
  // Production inhibit time (attribute 17), ms.
  std::uint16_t inhibit_ms = 0;
  // The allocation choice bits that made it (attribute 5 of the DeviceNet
  // object ORs them): 0x01, 0x02, 0x04, or 0x10 / 0x20 with 0x40.
  std::uint8_t allocated_as = 0;
  TimePoint watchdog_deadline = kNever;
};

inline constexpr unsigned kWatchdogMultiplier = 4;
inline constexpr std::uint16_t kExplicitDefaultEprMs = 2500;

// What a device does when its I/O connections change. Each is called after
// the change, so the connection's state is the new one; where the change
// deletes or alters it, `before` is the connection as it was (its state, its
// assemblies). Together they tell the device every time an I/O connection
// enters or leaves Established, so that what it produces can follow.
class ConnectionEvents {
 public:
  // An I/O connection has become Established: from Configuring by its
  // expected packet rate, or from Timed Out by a Connection Reset.
  virtual void on_io_established(std::uint16_t instance, TimePoint now) noexcept = 0;
  // The expected packet rate of an Established I/O connection was set again
  // (attribute 9); it stays Established.
  virtual void on_io_rate_changed(std::uint16_t instance, TimePoint now) noexcept = 0;
  // Released by the master: now Non-existent.
  virtual void on_io_released(std::uint16_t instance, const Connection& before,
                              TimePoint now) noexcept = 0;
  // Its watchdog expired and its timeout action has been taken: Timed Out,
  // Non-existent, Deferred Delete, or still Established (Auto Reset).
  virtual void on_io_timed_out(std::uint16_t instance, const Connection& before,
                               TimePoint now) noexcept = 0;

 protected:
  ~ConnectionEvents() = default;
};

struct ConnectionSetOptions {
  // The allocation choice bits the device supports; the others are refused
  // with 0x02/0x02. Acknowledge suppression (0x40) is a supported bit of its
  // own.
  std::uint8_t supported_choices = devicenet::allocation::kExplicit | devicenet::allocation::kPoll;
  // Expected packet rates are rounded up to this (bridge/PROTOCOL.md §7).
  Duration timer_resolution = milliseconds(10);
  // Watchdog timeout action of the explicit connection settable (to 1 or 3):
  // readings differ (bridge/PROTOCOL.md §7).
  bool explicit_timeout_action_settable = false;
  // The assemblies a new I/O connection's paths name, per instance.
  std::uint16_t poll_produced_assembly = 0;
  std::uint16_t poll_consumed_assembly = 0;
  std::uint16_t cos_produced_assembly = 0;
  std::uint16_t cos_consumed_assembly = 0;
  std::uint16_t strobe_produced_assembly = 0;  // a bit-strobe connection consumes the bitmap
};

class ConnectionSet {
 public:
  ConnectionSet(ConnectionSetOptions options, ConnectionEvents& events) noexcept;

  const ConnectionSetOptions& options() const noexcept { return options_; }

  // --- allocation (bridge/PROTOCOL.md §3) ---
  // 255 when no master owns the set.
  std::uint8_t owner() const noexcept { return owner_; }
  bool owned() const noexcept { return owner_ != devicenet::MacId::kNone; }
  std::uint8_t allocation_choice() const noexcept;
  Reply allocate(std::uint8_t choice, std::uint8_t allocator, TimePoint now) noexcept;
  Reply release(std::uint8_t choice, std::uint8_t requester, TimePoint now) noexcept;
  // Every connection gone, no owner (power-up, Communication Fault), with no event.
  void drop() noexcept;

  // --- the Connection object ---
  const Connection& explicit_connection() const noexcept { return explicit_; }
  const Connection& poll_connection() const noexcept { return poll_; }
  const Connection& cos_connection() const noexcept { return cos_; }
  const Connection& strobe_connection() const noexcept { return strobe_; }
  // Instances 1 to 4; nullptr for others.
  const Connection* connection(std::uint16_t instance) const noexcept;
  bool exists(std::uint16_t instance) const noexcept;
  bool established(std::uint16_t instance) const noexcept;
  bool explicit_established() const noexcept {
    return explicit_.state == ConnectionState::kEstablished;
  }
  // Attribute 9, rounded up to the timer resolution; `actual` receives the
  // value kept. Establishes a Configuring I/O connection.
  Reply set_expected_packet_rate(std::uint16_t instance, std::uint16_t requested_ms, TimePoint now,
                                 std::uint16_t& actual) noexcept;
  Reply set_watchdog_action(std::uint16_t instance, std::uint8_t action) noexcept;
  // The checks before a path (attributes 14/16) or the inhibit time (17) is
  // set: the I/O connection exists (0x16) and is Configuring (0x0C).
  Reply check_configuring(std::uint16_t instance) const noexcept;
  // Sets what check_configuring() allowed.
  void set_assembly(std::uint16_t instance, bool produced, std::uint16_t assembly) noexcept;
  void set_inhibit(std::uint16_t instance, std::uint16_t inhibit_ms) noexcept;
  // Connection Reset: restarts the watchdog; a timed-out I/O connection is
  // Established again (on_io_established).
  Reply reset(std::uint16_t instance, TimePoint now) noexcept;
  // A message the connection consumed restarts its watchdog.
  void consumed(std::uint16_t instance, TimePoint now) noexcept;

  // --- time ---
  // Watchdogs: timeout actions; with nothing left established afterwards
  // the set is dropped (bridge/PROTOCOL.md §7).
  void on_timer(TimePoint now) noexcept;
  TimePoint next_deadline() const noexcept;
  std::uint32_t watchdog_timeouts() const noexcept { return watchdog_timeouts_; }

 private:
  Connection* mutable_connection(std::uint16_t instance) noexcept;
  void open(Connection& c, std::uint8_t choice, std::uint16_t produced,
            std::uint16_t consumed) noexcept;
  void delete_io(std::uint16_t instance, Connection& c, TimePoint now) noexcept;
  void explicit_timeout() noexcept;
  void io_timeout(std::uint16_t instance, Connection& c, TimePoint now) noexcept;
  bool anything_established() const noexcept;
  bool io_established() const noexcept;
  void restart_watchdog(Connection& c, TimePoint now) const noexcept;
  std::uint16_t round_rate(std::uint16_t requested_ms) const noexcept;

  ConnectionSetOptions options_;
  ConnectionEvents& events_;
  std::uint8_t owner_ = devicenet::MacId::kNone;
  Connection explicit_;
  Connection poll_;
  Connection cos_;
  Connection strobe_;
  std::uint32_t watchdog_timeouts_ = 0;
};

}  // namespace dnbridge::sim
