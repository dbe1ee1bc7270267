#include "adapters/sim/generic/connection_set.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

namespace dnbridge::sim {

using cip::GeneralStatus;
using devicenet::MacId;
namespace alloc = devicenet::allocation;

namespace {

// Allocate/Release additional codes (bridge/PROTOCOL.md §3).
constexpr std::uint8_t kAllocationConflict = 0x01;
constexpr std::uint8_t kInvalidChoice = 0x02;

constexpr std::uint8_t kCosOrCyclic = alloc::kChangeOfState | alloc::kCyclic;

}  // namespace

ConnectionSet::ConnectionSet(ConnectionSetOptions options, ConnectionEvents& events) noexcept
    : options_(options), events_(events) {}

std::uint8_t ConnectionSet::allocation_choice() const noexcept {
  return static_cast<std::uint8_t>(explicit_.allocated_as | poll_.allocated_as |
                                   strobe_.allocated_as | cos_.allocated_as);
}

Reply ConnectionSet::allocate(std::uint8_t choice, std::uint8_t allocator, TimePoint now) noexcept {
  if (allocator > MacId::kMax) return reply_error(GeneralStatus::kInvalidParameter);
  if (owned() && owner_ != allocator) {
    return reply_error(GeneralStatus::kObjectStateConflict, kAllocationConflict);
  }
  if (choice == 0) return reply_error(GeneralStatus::kInvalidAttributeValue, kInvalidChoice);
  if ((choice & ~options_.supported_choices) != 0) {
    return reply_error(GeneralStatus::kResourceUnavailable, kInvalidChoice);
  }
  // Acknowledge suppression qualifies a change-of-state or cyclic
  // connection; instance 4 is one or the other (this simulator's reading
  // of a request for both: an invalid choice).
  const std::uint8_t cos = choice & kCosOrCyclic;
  if (((choice & alloc::kAckSuppression) != 0 && cos == 0) || cos == kCosOrCyclic) {
    return reply_error(GeneralStatus::kInvalidAttributeValue, kInvalidChoice);
  }
  const std::uint8_t allocated = allocation_choice();
  if ((choice & allocated & ~alloc::kAckSuppression) != 0 ||
      (cos != 0 && cos_.state != ConnectionState::kNonExistent)) {
    return reply_error(GeneralStatus::kAlreadyInRequestedMode, kInvalidChoice);
  }
  // I/O connections are configured through the explicit connection: one of
  // them must be requested or already there.
  if (((choice | allocated) & alloc::kExplicit) == 0) {
    return reply_error(GeneralStatus::kInvalidAttributeValue, kInvalidChoice);
  }
  owner_ = allocator;
  if ((choice & alloc::kExplicit) != 0) {
    open(explicit_, alloc::kExplicit, 0, 0);
    explicit_.state = ConnectionState::kEstablished;
    explicit_.expected_packet_rate_ms = kExplicitDefaultEprMs;
    explicit_.watchdog_action = WatchdogAction::kAutoDelete;
    restart_watchdog(explicit_, now);
  }
  if ((choice & alloc::kPoll) != 0) {
    open(poll_, alloc::kPoll, options_.poll_produced_assembly, options_.poll_consumed_assembly);
  }
  if ((choice & alloc::kBitStrobe) != 0) {
    open(strobe_, alloc::kBitStrobe, options_.strobe_produced_assembly, 0);
  }
  if (cos != 0) {
    open(cos_, static_cast<std::uint8_t>(choice & (kCosOrCyclic | alloc::kAckSuppression)),
         options_.cos_produced_assembly, options_.cos_consumed_assembly);
  }
  return kReplyOk;
}

void ConnectionSet::open(Connection& c, std::uint8_t choice, std::uint16_t produced,
                         std::uint16_t consumed) noexcept {
  c = Connection{};
  c.state = ConnectionState::kConfiguring;
  c.watchdog_action = WatchdogAction::kTimedOut;  // the I/O default
  c.produced_assembly = produced;
  c.consumed_assembly = consumed;
  c.allocated_as = choice;
}

Reply ConnectionSet::release(std::uint8_t choice, std::uint8_t requester, TimePoint now) noexcept {
  if (owned() && owner_ != requester) {
    return reply_error(GeneralStatus::kObjectStateConflict, kAllocationConflict);
  }
  if (choice == 0) return reply_error(GeneralStatus::kInvalidAttributeValue, kInvalidChoice);
  if ((choice & ~options_.supported_choices) != 0) {
    return reply_error(GeneralStatus::kResourceUnavailable, kInvalidChoice);
  }
  // Acknowledge suppression qualifies the connection it was allocated with;
  // alone it names nothing to release, as it is refused alone in Allocate.
  if ((choice & alloc::kAckSuppression) != 0 && (choice & kCosOrCyclic) == 0) {
    return reply_error(GeneralStatus::kInvalidAttributeValue, kInvalidChoice);
  }
  if ((choice & ~allocation_choice()) != 0) {
    return reply_error(GeneralStatus::kAlreadyInRequestedMode, kInvalidChoice);
  }
  if ((choice & alloc::kPoll) != 0) delete_io(connection_instance::kPoll, poll_, now);
  if ((choice & alloc::kBitStrobe) != 0) delete_io(connection_instance::kBitStrobe, strobe_, now);
  if ((choice & kCosOrCyclic) != 0) delete_io(connection_instance::kChangeOfState, cos_, now);
  if ((choice & alloc::kExplicit) != 0) explicit_ = Connection{};
  if (allocation_choice() == 0) owner_ = MacId::kNone;
  return kReplyOk;
}

void ConnectionSet::delete_io(std::uint16_t instance, Connection& c, TimePoint now) noexcept {
  const Connection before = std::exchange(c, Connection{});
  events_.on_io_released(instance, before, now);
}

void ConnectionSet::drop() noexcept {
  explicit_ = Connection{};
  poll_ = Connection{};
  cos_ = Connection{};
  strobe_ = Connection{};
  owner_ = MacId::kNone;
}

const Connection* ConnectionSet::connection(std::uint16_t instance) const noexcept {
  switch (instance) {
    case connection_instance::kExplicit:
      return &explicit_;
    case connection_instance::kPoll:
      return &poll_;
    case connection_instance::kBitStrobe:
      return &strobe_;
    case connection_instance::kChangeOfState:
      return &cos_;
    default:
      return nullptr;
  }
}

Connection* ConnectionSet::mutable_connection(std::uint16_t instance) noexcept {
  return const_cast<Connection*>(std::as_const(*this).connection(instance));
}

bool ConnectionSet::exists(std::uint16_t instance) const noexcept {
  const Connection* c = connection(instance);
  return c != nullptr && c->state != ConnectionState::kNonExistent;
}

bool ConnectionSet::established(std::uint16_t instance) const noexcept {
  const Connection* c = connection(instance);
  return c != nullptr && c->state == ConnectionState::kEstablished;
}

std::uint16_t ConnectionSet::round_rate(std::uint16_t requested_ms) const noexcept {
  const auto res = std::max<std::int64_t>(
      1, std::chrono::duration_cast<milliseconds>(options_.timer_resolution).count());
  const std::int64_t rounded = (requested_ms + res - 1) / res * res;
  if (rounded > 0xFFFF) return static_cast<std::uint16_t>(0xFFFF / res * res);
  return static_cast<std::uint16_t>(rounded);
}

// A change-of-state or cyclic connection consumes only acknowledgments: with
// them suppressed it has nothing to watch (this simulator's reading).
void ConnectionSet::restart_watchdog(Connection& c, TimePoint now) const noexcept {
  const bool nothing_consumed = (c.allocated_as & alloc::kAckSuppression) != 0;
  c.watchdog_deadline = c.expected_packet_rate_ms == 0 || nothing_consumed
                            ? kNever
                            : now + milliseconds(kWatchdogMultiplier * c.expected_packet_rate_ms);
}

Reply ConnectionSet::set_expected_packet_rate(std::uint16_t instance, std::uint16_t requested_ms,
                                              TimePoint now, std::uint16_t& actual) noexcept {
  Connection* c = mutable_connection(instance);
  if (c == nullptr || c->state == ConnectionState::kNonExistent) {
    return reply_error(GeneralStatus::kObjectDoesNotExist);
  }
  if (c->state != ConnectionState::kConfiguring && c->state != ConnectionState::kEstablished) {
    return reply_error(GeneralStatus::kObjectStateConflict);
  }
  actual = round_rate(requested_ms);
  c->expected_packet_rate_ms = actual;
  restart_watchdog(*c, now);
  if (instance == connection_instance::kExplicit) return kReplyOk;
  // Setting the rate is what moves a Configuring I/O connection to
  // Established (bridge/PROTOCOL.md §7).
  if (c->state == ConnectionState::kConfiguring) {
    c->state = ConnectionState::kEstablished;
    events_.on_io_established(instance, now);
  } else {
    events_.on_io_rate_changed(instance, now);
  }
  return kReplyOk;
}

Reply ConnectionSet::set_watchdog_action(std::uint16_t instance, std::uint8_t action) noexcept {
  Connection* c = mutable_connection(instance);
  if (c == nullptr || c->state == ConnectionState::kNonExistent) {
    return reply_error(GeneralStatus::kObjectDoesNotExist);
  }
  if (instance == connection_instance::kExplicit) {
    if (!options_.explicit_timeout_action_settable) {
      return reply_error(GeneralStatus::kAttributeNotSettable);
    }
    if (action != 1 && action != 3) return reply_error(GeneralStatus::kInvalidAttributeValue);
  } else if (action > 3) {
    return reply_error(GeneralStatus::kInvalidAttributeValue);
  }
  c->watchdog_action = static_cast<WatchdogAction>(action);
  return kReplyOk;
}

Reply ConnectionSet::check_configuring(std::uint16_t instance) const noexcept {
  const Connection* c = connection(instance);
  if (c == nullptr || c->state == ConnectionState::kNonExistent) {
    return reply_error(GeneralStatus::kObjectDoesNotExist);
  }
  if (c->state != ConnectionState::kConfiguring) {
    return reply_error(GeneralStatus::kObjectStateConflict);
  }
  return kReplyOk;
}

void ConnectionSet::set_assembly(std::uint16_t instance, bool produced,
                                 std::uint16_t assembly) noexcept {
  if (Connection* c = mutable_connection(instance)) {
    (produced ? c->produced_assembly : c->consumed_assembly) = assembly;
  }
}

void ConnectionSet::set_inhibit(std::uint16_t instance, std::uint16_t inhibit_ms) noexcept {
  if (Connection* c = mutable_connection(instance)) c->inhibit_ms = inhibit_ms;
}

Reply ConnectionSet::reset(std::uint16_t instance, TimePoint now) noexcept {
  Connection* c = mutable_connection(instance);
  if (c == nullptr || c->state == ConnectionState::kNonExistent) {
    return reply_error(GeneralStatus::kObjectDoesNotExist);
  }
  if (c->state == ConnectionState::kConfiguring) return kReplyOk;  // nothing to restart
  if (c->state == ConnectionState::kDeferredDelete) {
    return reply_error(GeneralStatus::kObjectStateConflict);
  }
  const bool was_established = c->state == ConnectionState::kEstablished;
  c->state = ConnectionState::kEstablished;
  restart_watchdog(*c, now);
  if (!was_established && instance != connection_instance::kExplicit) {
    events_.on_io_established(instance, now);
  }
  return kReplyOk;
}

void ConnectionSet::consumed(std::uint16_t instance, TimePoint now) noexcept {
  Connection* c = mutable_connection(instance);
  if (c != nullptr && c->state == ConnectionState::kEstablished) restart_watchdog(*c, now);
}

bool ConnectionSet::io_established() const noexcept {
  return poll_.state == ConnectionState::kEstablished ||
         strobe_.state == ConnectionState::kEstablished ||
         cos_.state == ConnectionState::kEstablished;
}

bool ConnectionSet::anything_established() const noexcept {
  return explicit_.state == ConnectionState::kEstablished || io_established();
}

void ConnectionSet::explicit_timeout() noexcept {
  if (explicit_.watchdog_action == WatchdogAction::kDeferredDelete && io_established()) {
    explicit_.state = ConnectionState::kDeferredDelete;
    explicit_.watchdog_deadline = kNever;
    return;
  }
  explicit_ = Connection{};  // auto delete
}

void ConnectionSet::io_timeout(std::uint16_t instance, Connection& c, TimePoint now) noexcept {
  const Connection before = c;
  switch (c.watchdog_action) {
    case WatchdogAction::kTimedOut:
      c.state = ConnectionState::kTimedOut;
      c.watchdog_deadline = kNever;
      break;
    case WatchdogAction::kAutoDelete:
      c = Connection{};
      break;
    case WatchdogAction::kAutoReset:
      restart_watchdog(c, now);
      break;
    case WatchdogAction::kDeferredDelete:
      if (explicit_.state == ConnectionState::kEstablished) {
        c.state = ConnectionState::kDeferredDelete;
        c.watchdog_deadline = kNever;
      } else {
        c = Connection{};
      }
      break;
  }
  events_.on_io_timed_out(instance, before, now);
}

void ConnectionSet::on_timer(TimePoint now) noexcept {
  bool expired = false;
  if (explicit_.state == ConnectionState::kEstablished && now >= explicit_.watchdog_deadline) {
    explicit_timeout();
    ++watchdog_timeouts_;
    expired = true;
  }
  if (poll_.state == ConnectionState::kEstablished && now >= poll_.watchdog_deadline) {
    io_timeout(connection_instance::kPoll, poll_, now);
    ++watchdog_timeouts_;
    expired = true;
  }
  for (const std::uint16_t instance :
       {connection_instance::kBitStrobe, connection_instance::kChangeOfState}) {
    Connection& c = *mutable_connection(instance);
    if (c.state == ConnectionState::kEstablished && now >= c.watchdog_deadline) {
      io_timeout(instance, c, now);
      ++watchdog_timeouts_;
      expired = true;
    }
  }
  // With nothing left established the slave drops the whole set; the master
  // must allocate again (bridge/PROTOCOL.md §7).
  if (expired && owned() && !anything_established()) drop();
}

TimePoint ConnectionSet::next_deadline() const noexcept {
  TimePoint t = kNever;
  for (const Connection* c : {&explicit_, &poll_, &strobe_, &cos_}) {
    if (c->state == ConnectionState::kEstablished) t = std::min(t, c->watchdog_deadline);
  }
  return t;
}

}  // namespace dnbridge::sim
