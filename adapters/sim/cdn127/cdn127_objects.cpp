// The class table, the lookups in it and the message router; the helpers
// the classes' attribute handlers share. The classes themselves:
// cdn127_objects_communication.cpp, cdn127_objects_points.cpp,
// cdn127_objects_device.cpp.
#include "adapters/sim/cdn127/cdn127_objects.hpp"

#include <array>
#include <optional>
#include <string_view>

#include "adapters/sim/cdn127/cdn127_objects_internal.hpp"
#include "adapters/sim/generic/attribute_codec.hpp"
#include "bridge/cip/data_types.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::sim {

using namespace cdn127_objects_detail;

namespace {

using cip::GeneralStatus;
namespace cls = profiles::cdn127::class_id;

}  // namespace

namespace cdn127_objects_detail {

// ---------------------------------------------------------------------------
// Helpers for attribute handlers.

Reply put_short_string(ByteWriter& w, std::string_view text) noexcept {
  std::array<std::uint8_t, 1 + cip::kMaxShortStringLength> buf{};
  auto size = cip::encode_short_string(text, buf);
  if (!size.ok()) return reply_error(GeneralStatus::kReplyDataTooLarge);
  w.bytes(Bytes(buf.data(), *size));
  return kReplyOk;
}

}  // namespace cdn127_objects_detail

namespace {

bool single_instance(const Cdn127Device&, std::uint16_t instance) noexcept { return instance == 1; }

// ---------------------------------------------------------------------------
// The class table. Columns: id, name, class attributes, instance attributes,
// Get (class), Get (instance), Set (instance), Reset (class), Reset
// (instance), Allocate, Release, instances.

const ClassDef kClasses[] = {
    {cls::kIdentity, cip::class_name(cls::kIdentity), kIdentityClass, kIdentityAttributes, true,
     true, false, nullptr, identity_reset, nullptr, nullptr, single_instance},
    {cls::kMessageRouter, cip::class_name(cls::kMessageRouter), kRouterClass, kRouterAttributes,
     true, true, false, nullptr, nullptr, nullptr, nullptr, single_instance},
    {cls::kDeviceNet, cip::class_name(cls::kDeviceNet), kDeviceNetClass, kDeviceNetAttributes, true,
     true, true, nullptr, nullptr, devicenet_allocate, devicenet_release, single_instance},
    {cls::kAssembly, cip::class_name(cls::kAssembly), kAssemblyClass, kAssemblyAttributes, true,
     true, true, nullptr, nullptr, nullptr, nullptr, assembly_exists},
    {cls::kConnection, cip::class_name(cls::kConnection), kConnectionClass, kConnectionAttributes,
     true, true, true, connection_class_reset, connection_reset, nullptr, nullptr,
     connection_exists},
    {cls::kDiscreteInputPoint, cip::class_name(cls::kDiscreteInputPoint), kDipClass, kDipAttributes,
     true, true, false, nullptr, nullptr, nullptr, nullptr, dip_exists},
    {cls::kDiscreteOutputPoint, cip::class_name(cls::kDiscreteOutputPoint), kDopClass,
     kDopAttributes, true, true, true, nullptr, nullptr, nullptr, nullptr, dop_exists},
    {cls::kAnalogInputPoint, cip::class_name(cls::kAnalogInputPoint), kAipClass, kAipAttributes,
     true, true, true, nullptr, nullptr, nullptr, nullptr, aip_exists},
    {cls::kAnalogOutputPoint, cip::class_name(cls::kAnalogOutputPoint), kAopClass, kAopAttributes,
     true, true, true, nullptr, nullptr, nullptr, nullptr, single_instance},
    {cls::kDeviceSupervisor, "Device Supervisor", kSupervisorClass, kSupervisorAttributes, true,
     true, true, nullptr, nullptr, nullptr, nullptr, single_instance},
    {cls::kConfiguration, "Configuration", kConfigurationClass, kConfigurationAttributes, true,
     true, true, nullptr, configuration_reset, nullptr, nullptr, single_instance},
};

// The attribute as this device's firmware has it: nullptr when the tables
// do not list it or the firmware lacks it (SlaveOptions::unsupported_attributes).
const AttributeDef* firmware_attribute(const Cdn127Device& device, const ClassDef& c,
                                       std::uint8_t attribute) noexcept {
  for (const ClassAttribute& missing : device.options().unsupported_attributes) {
    if (missing == ClassAttribute{c.id, attribute}) return nullptr;
  }
  return find_attribute(c, attribute);
}

// An attribute the manual lists Get/Set that this firmware has Get only
// (SlaveOptions::read_only_attributes).
bool firmware_read_only(const Cdn127Device& device, const ClassDef& c,
                        std::uint8_t attribute) noexcept {
  for (const ClassAttribute& fixed : device.options().read_only_attributes) {
    if (fixed == ClassAttribute{c.id, attribute}) return true;
  }
  return false;
}

Reply dispatch(Cdn127Device& device, const devicenet::RequestMessage& req, std::uint8_t requester,
               TimePoint now, ByteWriter& w) noexcept {
  const ClassDef* c = find_class(req.class_id);
  if (c == nullptr) return reply_error(GeneralStatus::kObjectDoesNotExist);
  const bool class_level = req.instance_id == 0;
  if (!class_level && !c->has_instance(device, req.instance_id)) {
    return reply_error(GeneralStatus::kObjectDoesNotExist);
  }
  const RequestContext ctx{device, req.instance_id, requester, now};
  const auto not_supported = reply_error(GeneralStatus::kServiceNotSupported);

  switch (static_cast<cip::Service>(req.service)) {
    case cip::Service::kGetAttributeSingle: {
      if (!(class_level ? c->class_get : c->instance_get)) return not_supported;
      if (!req.attribute) return reply_error(GeneralStatus::kNotEnoughData);
      if (!req.data.empty()) return reply_error(GeneralStatus::kTooMuchData);
      if (class_level) {
        for (const ClassAttributeDef& a : c->class_attributes) {
          if (a.id == *req.attribute) return put_u16(w, a.value);
        }
        return reply_error(GeneralStatus::kAttributeNotSupported);
      }
      const AttributeDef* a = firmware_attribute(device, *c, *req.attribute);
      if (a == nullptr) return reply_error(GeneralStatus::kAttributeNotSupported);
      return a->get(ctx, w);
    }
    case cip::Service::kSetAttributeSingle: {
      // No class lists Set at class level.
      if (class_level || !c->instance_set) return not_supported;
      if (!req.attribute) return reply_error(GeneralStatus::kNotEnoughData);
      const AttributeDef* a = firmware_attribute(device, *c, *req.attribute);
      if (a == nullptr) return reply_error(GeneralStatus::kAttributeNotSupported);
      if (a->access != Access::kGetSet || a->set == nullptr ||
          firmware_read_only(device, *c, *req.attribute)) {
        return reply_error(GeneralStatus::kAttributeNotSettable);
      }
      return a->set(ctx, req.data, w);
    }
    case cip::Service::kReset: {
      ServiceHandler h = class_level ? c->class_reset : c->instance_reset;
      return h != nullptr ? h(ctx, req.data, w) : not_supported;
    }
    case cip::Service::kAllocateMasterSlave:
      return (!class_level && c->allocate != nullptr) ? c->allocate(ctx, req.data, w)
                                                      : not_supported;
    case cip::Service::kReleaseMasterSlave:
      return (!class_level && c->release != nullptr) ? c->release(ctx, req.data, w) : not_supported;
    case cip::Service::kGetAttributesAll:
    case cip::Service::kSetAttributesAll:
    case cip::Service::kCreate:
    case cip::Service::kDelete:
    case cip::Service::kApplyAttributes:
    case cip::Service::kErrorResponse:
      break;
  }
  return not_supported;
}

}  // namespace

std::span<const ClassDef> object_classes() noexcept { return kClasses; }

const ClassDef* find_class(std::uint16_t class_id) noexcept {
  for (const ClassDef& c : kClasses) {
    if (c.id == class_id) return &c;
  }
  return nullptr;
}

const AttributeDef* find_attribute(const ClassDef& c, std::uint8_t attribute) noexcept {
  for (const AttributeDef& a : c.instance_attributes) {
    if (a.id == attribute) return &a;
  }
  return nullptr;
}

std::size_t execute_request(Cdn127Device& device, const devicenet::RequestMessage& request,
                            std::uint8_t requester, TimePoint now, MutableBytes out) noexcept {
  std::array<std::uint8_t, 64> data{};
  ByteWriter w(data);
  const Reply r = dispatch(device, request, requester, now, w);
  return encode_reply(request.service, r, w, out);
}

}  // namespace dnbridge::sim
