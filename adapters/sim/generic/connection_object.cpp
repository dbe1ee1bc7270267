#include "adapters/sim/generic/connection_object.hpp"

#include <array>
#include <optional>

#include "adapters/sim/generic/attribute_codec.hpp"
#include "bridge/cip/epath.hpp"
#include "bridge/cip/objects.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"
#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::sim {
namespace {

using cip::GeneralStatus;
using devicenet::Group1Message;
using devicenet::Group2Message;
namespace attr = cip::connection_attr;
namespace alloc = devicenet::allocation;

bool is_explicit(std::uint16_t instance) noexcept {
  return instance == connection_instance::kExplicit;
}

// Produced and consumed connection IDs of each instance (bridge/PROTOCOL.md
// §1); the bit-strobe command carries its master's MAC (`owner`).
std::uint16_t connection_id(devicenet::MacId mac, std::uint8_t owner, std::uint16_t instance,
                            bool produced) noexcept {
  switch (instance) {
    case connection_instance::kBitStrobe:
      return static_cast<std::uint16_t>(
          produced ? devicenet::group1_id(Group1Message::kSlaveBitStrobeResponse, mac)
                   : devicenet::group2_id(devicenet::MacId::from_bits(owner),
                                          Group2Message::kMasterBitStrobeCommand));
    case connection_instance::kExplicit:
      return static_cast<std::uint16_t>(
          devicenet::group2_id(mac, produced ? Group2Message::kSlaveExplicitResponse
                                             : Group2Message::kMasterExplicitRequest));
    case connection_instance::kChangeOfState:
      return static_cast<std::uint16_t>(
          produced ? devicenet::group1_id(Group1Message::kSlaveCosCyclic, mac)
                   : devicenet::group2_id(mac, Group2Message::kMasterCosCyclicAck));
    default:
      return static_cast<std::uint16_t>(
          produced ? devicenet::group1_id(Group1Message::kSlavePollResponse, mac)
                   : devicenet::group2_id(mac, Group2Message::kMasterIoPoll));
  }
}

std::uint8_t transport_class_trigger(const Connection& c, std::uint16_t instance) noexcept {
  if (is_explicit(instance)) return 0x83;
  if (instance != connection_instance::kChangeOfState) return 0x82;
  const std::uint8_t trigger = (c.allocated_as & alloc::kChangeOfState) != 0 ? 0x10 : 0x00;
  const std::uint8_t transport = (c.allocated_as & alloc::kAckSuppression) != 0 ? 0x00 : 0x02;
  return static_cast<std::uint8_t>(trigger | transport);
}

// The path of an I/O connection's data: the assembly's attribute 3; none
// for the explicit connection or an assembly of 0.
std::optional<cip::EPath> data_path(const Connection& c, std::uint16_t instance,
                                    bool produced) noexcept {
  const std::uint16_t assembly = produced ? c.produced_assembly : c.consumed_assembly;
  if (is_explicit(instance) || assembly == 0) return std::nullopt;
  cip::EPath p;
  p.class_id = cip::class_id::kAssembly;
  p.instance_id = assembly;
  p.attribute = 3;
  return p;
}

Reply put_path(const Connection& c, std::uint16_t instance, bool produced, bool length_only,
               ByteWriter& w) noexcept {
  const auto path = data_path(c, instance, produced);
  std::array<std::uint8_t, 16> buf{};
  std::size_t n = 0;
  if (path) {
    auto size = cip::encode(*path, buf);
    if (!size.ok()) return reply_error(GeneralStatus::kReplyDataTooLarge);
    n = *size;
  }
  if (length_only) return put_u8(w, static_cast<std::uint8_t>(n));
  w.bytes(Bytes(buf.data(), n));
  return kReplyOk;
}

// Paths select the I/O connection's assemblies while it is Configuring
// (bridge/PROTOCOL.md §8).
Reply set_path(ConnectionSet& set, const IoAssemblies& io, std::uint16_t instance, bool produced,
               Bytes data) noexcept {
  if (is_explicit(instance) || io.paths_fixed()) {
    return reply_error(GeneralStatus::kAttributeNotSettable);
  }
  auto path = cip::decode_epath(data);
  if (!path.ok() || path->class_id != std::optional<std::uint32_t>(cip::class_id::kAssembly) ||
      !path->instance_id || *path->instance_id > io.max_assembly() || path->connection_point ||
      path->attribute != std::optional<std::uint32_t>(3)) {
    return reply_error(GeneralStatus::kInvalidAttributeValue);
  }
  const Reply r = set.check_configuring(instance);
  if (!r.ok()) return r;
  const auto assembly = static_cast<std::uint16_t>(*path->instance_id);
  if (!io.assembly_allowed(instance, produced, assembly)) {
    return reply_error(GeneralStatus::kInvalidAttributeValue);
  }
  set.set_assembly(instance, produced, assembly);
  return kReplyOk;
}

}  // namespace

bool connection_attribute_exists(std::uint8_t attribute) noexcept {
  return (attribute >= attr::kState && attribute <= attr::kExpectedPacketRate) ||
         (attribute >= attr::kWatchdogTimeoutAction && attribute <= attr::kInhibitTime);
}

bool connection_attribute_settable(std::uint16_t instance, std::uint8_t attribute) noexcept {
  switch (attribute) {
    case attr::kExpectedPacketRate:
    case attr::kWatchdogTimeoutAction:
    case attr::kProducedPath:
      return true;
    case attr::kConsumedPath:
      // The change-of-state connection consumes the master's
      // acknowledgments, no data, and the bit-strobe connection the
      // command's bitmap: there is no consumed path to choose.
      return instance != connection_instance::kChangeOfState &&
             instance != connection_instance::kBitStrobe;
    case attr::kInhibitTime:
      return instance == connection_instance::kChangeOfState;
    default:
      return false;
  }
}

Reply get_connection_attribute(const ConnectionSet& set, devicenet::MacId mac,
                               const IoAssemblies& io, std::uint16_t instance,
                               std::uint8_t attribute, ByteWriter& w) noexcept {
  const Connection* c = set.connection(instance);
  if (c == nullptr) return reply_error(GeneralStatus::kObjectDoesNotExist);
  switch (attribute) {
    case attr::kState:
      return put_u8(w, static_cast<std::uint8_t>(c->state));
    case attr::kInstanceType:
      return put_u8(w, is_explicit(instance) ? 0 : 1);
    case attr::kTransportClassTrigger:
      return put_u8(w, transport_class_trigger(*c, instance));
    case attr::kProducedConnectionId:
      return put_u16(w, connection_id(mac, set.owner(), instance, true));
    case attr::kConsumedConnectionId:
      return put_u16(w, connection_id(mac, set.owner(), instance, false));
    case attr::kInitialCommCharacteristics:
      return put_u8(w, is_explicit(instance) ? 0x21 : 0x01);
    case attr::kProducedSize:
      return put_u16(w, io.connection_size(instance, true));
    case attr::kConsumedSize:
      return put_u16(w, io.connection_size(instance, false));
    case attr::kExpectedPacketRate:
      return put_u16(w, c->expected_packet_rate_ms);
    case attr::kWatchdogTimeoutAction:
      return put_u8(w, static_cast<std::uint8_t>(c->watchdog_action));
    case attr::kProducedPathLength:
      return put_path(*c, instance, true, true, w);
    case attr::kProducedPath:
      return put_path(*c, instance, true, false, w);
    case attr::kConsumedPathLength:
      return put_path(*c, instance, false, true, w);
    case attr::kConsumedPath:
      return put_path(*c, instance, false, false, w);
    case attr::kInhibitTime:
      return put_u16(w, c->inhibit_ms);
    default:
      return reply_error(GeneralStatus::kAttributeNotSupported);
  }
}

Reply set_connection_attribute(ConnectionSet& set, const IoAssemblies& io, std::uint16_t instance,
                               std::uint8_t attribute, Bytes data, TimePoint now,
                               ByteWriter& w) noexcept {
  switch (attribute) {
    case attr::kExpectedPacketRate: {
      // The response carries the rate kept, rounded up (bridge/PROTOCOL.md §7).
      std::uint16_t requested = 0;
      Reply r = read_u16(data, requested);
      if (!r.ok()) return r;
      std::uint16_t actual = 0;
      r = set.set_expected_packet_rate(instance, requested, now, actual);
      if (r.ok()) w.u16le(actual);
      return r;
    }
    case attr::kWatchdogTimeoutAction: {
      std::uint8_t v = 0;
      Reply r = read_u8(data, v);
      return r.ok() ? set.set_watchdog_action(instance, v) : r;
    }
    case attr::kProducedPath:
    case attr::kConsumedPath:
      return set_path(set, io, instance, attribute == attr::kProducedPath, data);
    case attr::kInhibitTime: {
      if (!connection_attribute_settable(instance, attribute)) {
        return reply_error(GeneralStatus::kAttributeNotSettable);
      }
      std::uint16_t v = 0;
      Reply r = read_u16(data, v);
      if (r.ok()) r = set.check_configuring(instance);
      if (r.ok()) set.set_inhibit(instance, v);
      return r;
    }
    default:
      return reply_error(GeneralStatus::kAttributeNotSettable);
  }
}

Reply reset_connection(ConnectionSet& set, std::uint16_t instance, Bytes data,
                       TimePoint now) noexcept {
  if (!data.empty()) return reply_error(GeneralStatus::kTooMuchData);
  return set.reset(instance, now);
}

Reply reset_connection_class(ConnectionSet& set, Bytes data, TimePoint now) noexcept {
  if (!data.empty()) return reply_error(GeneralStatus::kTooMuchData);
  for (const std::uint16_t i :
       {connection_instance::kExplicit, connection_instance::kPoll, connection_instance::kBitStrobe,
        connection_instance::kChangeOfState}) {
    if (set.exists(i)) (void)set.reset(i, now);
  }
  return kReplyOk;
}

Reply allocate_service(ConnectionSet& set, Bytes data, TimePoint now, ByteWriter& w) noexcept {
  Reply r = expect_size(data, 2);
  if (!r.ok()) return r;
  r = set.allocate(data[0], data[1], now);
  if (r.ok()) w.u8(static_cast<std::uint8_t>(devicenet::BodyFormat::k8_8));
  return r;
}

Reply release_service(ConnectionSet& set, Bytes data, std::uint8_t requester,
                      TimePoint now) noexcept {
  Reply r = expect_size(data, 1);
  if (!r.ok()) return r;
  return set.release(data[0], requester, now);
}

Reply put_allocation_information(const ConnectionSet& set, ByteWriter& w) noexcept {
  w.u8(set.allocation_choice());
  w.u8(set.owner());
  return kReplyOk;
}

}  // namespace dnbridge::sim
