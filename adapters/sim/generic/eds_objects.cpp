#include "adapters/sim/generic/eds_objects.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

#include "bridge/cip/assembly.hpp"
#include "bridge/cip/data_types.hpp"
#include "bridge/cip/objects.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/profiles/eds/io_layout.hpp"

namespace dnbridge::sim {
namespace {

using cip::GeneralStatus;

constexpr std::uint16_t kParameterClass = cip::class_id::kParameter;
constexpr std::uint16_t kAckHandlerClass = cip::class_id::kAcknowledgeHandler;

// A parameter's value as bytes (little-endian, its data size) from a number.
std::vector<std::uint8_t> encode_value(const profiles::eds::Param& p, double v) {
  std::vector<std::uint8_t> out(p.size, 0);
  if (p.type.is_float) {
    if (p.size == 4) {
      const float f =
          std::abs(v) <= std::numeric_limits<float>::max() ? static_cast<float>(v) : 0.0f;
      const auto bits = std::bit_cast<std::uint32_t>(f);
      for (std::size_t i = 0; i < 4; ++i) out[i] = static_cast<std::uint8_t>(bits >> (8 * i));
    } else if (p.size == 8) {
      const auto bits = std::bit_cast<std::uint64_t>(v);
      for (std::size_t i = 0; i < 8; ++i) out[i] = static_cast<std::uint8_t>(bits >> (8 * i));
    }
    return out;
  }
  if (p.type.size == 0) return out;  // strings: no value kept
  // In the type's range (the EDS reader checked the limits; a default of
  // 2^64 - 1 reads as 2^64 in a double).
  const double lo = p.type.is_signed ? -std::ldexp(1.0, 8 * p.size - 1) : 0.0;
  const double hi = std::ldexp(1.0, 8 * p.size - (p.type.is_signed ? 1 : 0));
  const double clamped = std::isfinite(v) ? std::clamp(v, lo, std::nextafter(hi, 0.0)) : 0.0;
  const auto bits = clamped < 0 ? static_cast<std::uint64_t>(static_cast<std::int64_t>(clamped))
                                : static_cast<std::uint64_t>(clamped);
  for (std::size_t i = 0; i < out.size() && i < 8; ++i) {
    out[i] = static_cast<std::uint8_t>(bits >> (8 * i));
  }
  return out;
}

// The number `value` holds, as its type reads it.
std::optional<double> decode_value(const profiles::eds::Param& p, Bytes value) {
  if (value.size() != p.size || p.type.size == 0) return std::nullopt;
  std::uint64_t bits = little_endian(value);
  if (p.type.is_float) {
    if (p.size == 4) return std::bit_cast<float>(static_cast<std::uint32_t>(bits));
    return std::bit_cast<double>(bits);
  }
  if (p.type.is_signed && p.size < 8) {
    const unsigned width = 8u * p.size;
    if ((bits >> (width - 1)) & 1u) bits |= ~std::uint64_t{0} << width;
  }
  return p.type.is_signed ? static_cast<double>(static_cast<std::int64_t>(bits))
                          : static_cast<double>(bits);
}

std::vector<std::uint8_t> encode_path(const cip::EPath& path) {
  std::array<std::uint8_t, 32> buf{};
  auto n = cip::encode(path, MutableBytes(buf));
  if (!n) return {};
  return {buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(*n)};
}

}  // namespace

EdsObjects::EdsObjects(profiles::eds::EdsFile file, std::uint32_t serial_number, bool member_lists)
    : file_(std::move(file)), serial_number_(serial_number), member_lists_(member_lists) {
  for (const auto& p : file_.params) {
    values_[p.number] = encode_value(p, p.default_value.value_or(0.0));
  }
}

std::vector<std::uint8_t> EdsObjects::param_value(unsigned number) const {
  auto it = values_.find(number);
  return it == values_.end() ? std::vector<std::uint8_t>{} : it->second;
}

std::optional<double> EdsObjects::param_number(unsigned number) const {
  const profiles::eds::Param* p = file_.param(number);
  if (p == nullptr) return std::nullopt;
  const auto value = param_value(number);
  return decode_value(*p, Bytes(value.data(), value.size()));
}

bool EdsObjects::set_param_value(unsigned number, Bytes value) {
  auto it = values_.find(number);
  if (it == values_.end() || it->second.size() != value.size()) return false;
  it->second.assign(value.begin(), value.end());
  return true;
}

bool EdsObjects::set_param_number(unsigned number, double value) {
  const profiles::eds::Param* p = file_.param(number);
  if (p == nullptr || p->type.size == 0) return false;
  if (!profiles::eds::to_raw(p->type, static_cast<std::uint16_t>(p->size * 8), value)) return false;
  const auto bytes = encode_value(*p, value);
  return set_param_value(number, Bytes(bytes.data(), bytes.size()));
}

const profiles::eds::Assembly* EdsObjects::assembly(unsigned instance) const noexcept {
  return file_.assembly_at(cip::EPath{cip::class_id::kAssembly, instance, std::nullopt, 3});
}

const profiles::eds::Assembly* EdsObjects::assembly_numbered(unsigned number) const noexcept {
  for (const auto& a : file_.assemblies) {
    if (a.number == number) return &a;
  }
  return nullptr;
}

std::vector<std::uint8_t> EdsObjects::assembly_data(unsigned instance) const {
  const profiles::eds::Assembly* a = assembly(instance);
  return a == nullptr ? std::vector<std::uint8_t>{} : packed(*a, 0);
}

std::vector<std::uint8_t> EdsObjects::packed(const profiles::eds::Assembly& assembly,
                                             unsigned depth) const {
  const profiles::eds::Assembly* a = &assembly;
  const std::uint32_t total = a->size_bits();
  std::vector<std::uint8_t> out((total + 7) / 8, 0);
  std::uint32_t at = 0;
  const auto put = [&](const std::vector<std::uint8_t>& from, std::uint32_t bits) {
    for (std::uint32_t i = 0; i < bits && i / 8 < from.size() && at + i < total; ++i) {
      if ((static_cast<unsigned>(from[i / 8]) >> (i % 8)) & 1u) {
        out[(at + i) / 8] = static_cast<std::uint8_t>(out[(at + i) / 8] | (1u << ((at + i) % 8)));
      }
    }
  };
  for (const auto& m : a->members) {
    if (m.kind == profiles::eds::Member::Kind::kParam) put(param_value(m.number), m.bits);
    if (m.kind == profiles::eds::Member::Kind::kPath) {
      if (auto it = path_values_.find(cip::encoded(m.path)); it != path_values_.end()) {
        put(it->second, m.bits);
      }
    }
    // Nested assemblies, kMaxNesting deep (the EDS reader refuses cycles).
    if (m.kind == profiles::eds::Member::Kind::kAssembly && depth < kMaxNesting) {
      if (const profiles::eds::Assembly* nested = assembly_numbered(m.number)) {
        put(packed(*nested, depth + 1), m.bits);
      }
    }
    at += m.bits;
  }
  return out;
}

bool EdsObjects::set_assembly_data(unsigned instance, Bytes data) {
  const profiles::eds::Assembly* a = assembly(instance);
  if (a == nullptr || data.size() != (a->size_bits() + 7) / 8) return false;
  unpack(*a, data, 0, 0);
  return true;
}

// The inverse of packed(): each parameter member's bits from `data`, the
// assembly starting at bit `at`; a parameter's bits past its member's stay.
void EdsObjects::unpack(const profiles::eds::Assembly& assembly, Bytes data, std::uint32_t at,
                        unsigned depth) {
  const auto bit = [&](std::uint32_t i) {
    return i / 8 < data.size() && ((static_cast<unsigned>(data[i / 8]) >> (i % 8)) & 1u) != 0;
  };
  for (const auto& m : assembly.members) {
    if (m.kind == profiles::eds::Member::Kind::kParam) {
      auto it = values_.find(m.number);
      if (it != values_.end()) {
        auto& value = it->second;
        for (std::uint32_t i = 0; i < m.bits && i / 8 < value.size(); ++i) {
          const auto mask = static_cast<std::uint8_t>(1u << (i % 8));
          value[i / 8] =
              static_cast<std::uint8_t>(bit(at + i) ? value[i / 8] | mask : value[i / 8] & ~mask);
        }
      }
    }
    if (m.kind == profiles::eds::Member::Kind::kPath) {
      auto& value = path_values_[cip::encoded(m.path)];
      value.resize(std::max<std::size_t>(value.size(), (m.bits + 7u) / 8u), 0);
      for (std::uint32_t i = 0; i < m.bits; ++i) {
        const auto mask = static_cast<std::uint8_t>(1u << (i % 8));
        value[i / 8] =
            static_cast<std::uint8_t>(bit(at + i) ? value[i / 8] | mask : value[i / 8] & ~mask);
      }
    }
    if (m.kind == profiles::eds::Member::Kind::kAssembly && depth < kMaxNesting) {
      if (const profiles::eds::Assembly* nested = assembly_numbered(m.number)) {
        unpack(*nested, data, at, depth + 1);
      }
    }
    at += m.bits;
  }
}

std::vector<cip::AssemblyMember> EdsObjects::member_list(const profiles::eds::Assembly& a) const {
  std::vector<cip::AssemblyMember> list;
  for (const auto& m : a.members) {
    cip::AssemblyMember out;
    out.bits = m.bits;
    std::optional<cip::EPath> path;
    switch (m.kind) {
      case profiles::eds::Member::Kind::kPadding:
        break;
      case profiles::eds::Member::Kind::kPath:
        path = m.path;
        break;
      case profiles::eds::Member::Kind::kParam: {
        const profiles::eds::Param* p = file_.param(m.number);
        path = p != nullptr && !p->link.empty()
                   ? p->link
                   : cip::EPath{kParameterClass, m.number, std::nullopt, 1};
        break;
      }
      case profiles::eds::Member::Kind::kAssembly: {
        const profiles::eds::Assembly* nested = assembly_numbered(m.number);
        if (nested != nullptr) path = nested->path;
        break;
      }
    }
    if (path) {
      out.path_bytes = encode_path(*path);
      out.path = *path;
    }
    list.push_back(std::move(out));
  }
  return list;
}

EdsObjects::Outcome EdsObjects::get_identity(std::uint8_t attribute, ByteWriter& out) const {
  const auto& d = file_.device;
  switch (attribute) {
    case cip::identity_attr::kVendor:
      out.u16le(d.vendor_code);
      break;
    case cip::identity_attr::kProductType:
      out.u16le(d.product_type);
      break;
    case cip::identity_attr::kProductCode:
      out.u16le(d.product_code);
      break;
    case cip::identity_attr::kRevision:
      out.u8(d.major_revision);
      out.u8(d.minor_revision);
      break;
    case cip::identity_attr::kStatus:
      out.u16le(0);
      break;
    case cip::identity_attr::kSerialNumber:
      out.u32le(serial_number_);
      break;
    case cip::identity_attr::kProductName: {
      const std::string_view name = d.product_name;
      if (name.size() > cip::kMaxShortStringLength) return {GeneralStatus::kReplyDataTooLarge};
      out.u8(static_cast<std::uint8_t>(name.size()));
      out.bytes(Bytes(reinterpret_cast<const std::uint8_t*>(name.data()), name.size()));
      break;
    }
    default:
      return {GeneralStatus::kAttributeNotSupported};
  }
  return {};
}

EdsObjects::Outcome EdsObjects::get_assembly(std::uint16_t instance, std::uint8_t attribute,
                                             ByteWriter& out) const {
  if (instance == 0) {
    std::uint32_t max = 0;
    for (const auto& a : file_.assemblies) max = std::max(max, a.path.instance_id.value_or(0));
    if (attribute == cip::class_attr::kRevision) {
      out.u16le(1);
    } else if (attribute == cip::class_attr::kMaxInstance) {
      out.u16le(static_cast<std::uint16_t>(max));
    } else {
      return {GeneralStatus::kAttributeNotSupported};
    }
    return {};
  }
  const profiles::eds::Assembly* a = assembly(instance);
  if (a == nullptr) return {GeneralStatus::kObjectDoesNotExist};
  if (!member_lists_ && attribute != cip::assembly_attr::kData) {
    return {GeneralStatus::kAttributeNotSupported};
  }
  switch (attribute) {
    case cip::assembly_attr::kMemberCount:
      out.u16le(static_cast<std::uint16_t>(a->members.size()));
      break;
    case cip::assembly_attr::kMemberList: {
      const auto bytes = cip::encode_member_list(member_list(*a));
      out.bytes(Bytes(bytes.data(), bytes.size()));
      break;
    }
    case cip::assembly_attr::kData: {
      const auto data = assembly_data(instance);
      out.bytes(Bytes(data.data(), data.size()));
      break;
    }
    default:
      return {GeneralStatus::kAttributeNotSupported};
  }
  return {};
}

EdsObjects::Outcome EdsObjects::get_parameter(std::uint16_t instance, std::uint8_t attribute,
                                              ByteWriter& out) const {
  if (instance == 0) {
    if (attribute != cip::class_attr::kMaxInstance) return {GeneralStatus::kAttributeNotSupported};
    unsigned max = 0;
    for (const auto& p : file_.params) max = std::max(max, p.number);
    out.u16le(static_cast<std::uint16_t>(max));
    return {};
  }
  const profiles::eds::Param* p = file_.param(instance);
  if (p == nullptr) return {GeneralStatus::kObjectDoesNotExist};
  if (attribute != 1) return {GeneralStatus::kAttributeNotSupported};
  if (p->type.size == 0) {
    // A string parameter is kept empty: its length alone.
    if (p->type.code == 0xD0)
      out.u16le(0);
    else
      out.u8(0);
    return {};
  }
  const auto value = param_value(instance);
  out.bytes(Bytes(value.data(), value.size()));
  return {};
}

EdsObjects::Outcome EdsObjects::get_ack_handler(std::uint16_t instance, std::uint8_t attribute,
                                                ByteWriter& out) const {
  if (instance == 0) {
    if (attribute != cip::class_attr::kRevision && attribute != cip::class_attr::kMaxInstance) {
      return {GeneralStatus::kAttributeNotSupported};
    }
    out.u16le(1);
    return {};
  }
  if (instance != 1) return {GeneralStatus::kObjectDoesNotExist};
  switch (attribute) {
    case 1:
      out.u16le(ack_.ack_timer_ms);
      break;
    case 2:
      out.u8(ack_.retry_limit);
      break;
    case 3:
      out.u16le(ack_.cos_producing_instance);
      break;
    case 4:
      out.u8(1);
      break;
    case 5:
      if (ack_.cos_acknowledged) {
        out.u8(1);
        out.u8(static_cast<std::uint8_t>(ack_.cos_producing_instance));
      } else {
        out.u8(0);
      }
      break;
    default:
      return {GeneralStatus::kAttributeNotSupported};
  }
  return {};
}

EdsObjects::Outcome EdsObjects::get(const devicenet::RequestMessage& r, ByteWriter& out) const {
  const std::uint8_t attribute = *r.attribute;
  switch (r.class_id) {
    case cip::class_id::kIdentity:
      if (r.instance_id == 0) {
        if (attribute != cip::class_attr::kRevision && attribute != cip::class_attr::kMaxInstance) {
          return {GeneralStatus::kAttributeNotSupported};
        }
        out.u16le(1);
        return {};
      }
      return get_identity(attribute, out);
    case cip::class_id::kAssembly:
      return get_assembly(r.instance_id, attribute, out);
    case kParameterClass:
      return get_parameter(r.instance_id, attribute, out);
    case kAckHandlerClass:
      return get_ack_handler(r.instance_id, attribute, out);
    default:
      return {GeneralStatus::kObjectDoesNotExist};
  }
}

bool EdsObjects::exists(std::uint16_t class_id, std::uint16_t instance) const noexcept {
  if (instance == 0) {
    return class_id == cip::class_id::kIdentity || class_id == cip::class_id::kAssembly ||
           class_id == kParameterClass || class_id == kAckHandlerClass;
  }
  switch (class_id) {
    case cip::class_id::kIdentity:
    case kAckHandlerClass:
      return instance == 1;
    case cip::class_id::kAssembly:
      return assembly(instance) != nullptr;
    case kParameterClass:
      return file_.param(instance) != nullptr;
    default:
      return false;
  }
}

EdsObjects::Outcome EdsObjects::set(const devicenet::RequestMessage& r) {
  const std::uint8_t attribute = *r.attribute;
  const auto size_check = [&](std::size_t want) -> std::optional<Outcome> {
    if (r.data.size() < want) return Outcome{GeneralStatus::kNotEnoughData};
    if (r.data.size() > want) return Outcome{GeneralStatus::kTooMuchData};
    return std::nullopt;
  };
  // Supported at all (as a Get would answer), then settable.
  ByteWriter probe(MutableBytes{});
  const Outcome supported = get(r, probe);
  if (supported.status == GeneralStatus::kAttributeNotSupported) return supported;
  if (r.class_id == kParameterClass && attribute == 1) {
    const profiles::eds::Param* p = file_.param(r.instance_id);
    if (p->read_only() || p->type.size == 0) return {GeneralStatus::kAttributeNotSettable};
    if (auto bad = size_check(p->size)) return *bad;
    const auto v = decode_value(*p, r.data);
    if (!v || !std::isfinite(*v)) return {GeneralStatus::kInvalidAttributeValue};
    // A REAL is compared with its limits as REALs.
    const auto limit = [&](double l) {
      return p->size == 4 && p->type.is_float ? double{static_cast<float>(l)} : l;
    };
    if ((p->minimum && *v < limit(*p->minimum)) || (p->maximum && *v > limit(*p->maximum))) {
      return {GeneralStatus::kInvalidAttributeValue};
    }
    values_[p->number].assign(r.data.begin(), r.data.end());
    return {};
  }
  if (r.class_id == kAckHandlerClass) {
    switch (attribute) {
      case 1: {
        if (auto bad = size_check(2)) return *bad;
        const auto v = static_cast<std::uint16_t>(r.data[0] | r.data[1] << 8);
        if (v == 0) return {GeneralStatus::kInvalidAttributeValue};  // 1..65535
        ack_.ack_timer_ms = v;
        return {};
      }
      case 2:
        if (auto bad = size_check(1)) return *bad;
        ack_.retry_limit = r.data[0];
        return {};
      case 3: {
        if (auto bad = size_check(2)) return *bad;
        const auto v = static_cast<std::uint16_t>(r.data[0] | r.data[1] << 8);
        // The ack list holds USINT instances.
        if (v == 0 || v > 0xFF) return {GeneralStatus::kInvalidAttributeValue};
        ack_.cos_producing_instance = v;
        return {};
      }
      default:
        break;
    }
  }
  return {GeneralStatus::kAttributeNotSettable};
}

std::size_t EdsObjects::execute(const devicenet::RequestMessage& request, MutableBytes out) {
  std::array<std::uint8_t, devicenet::kMaxExplicitMessage> data{};
  ByteWriter w{MutableBytes(data)};
  Outcome o;
  // In the order the CDN127 simulator checks (cdn127_objects.cpp, dispatch).
  const auto service = static_cast<cip::Service>(request.service);
  const bool get_single = service == cip::Service::kGetAttributeSingle;
  const bool set_single = service == cip::Service::kSetAttributeSingle;
  if (!exists(request.class_id, request.instance_id)) {
    o = {GeneralStatus::kObjectDoesNotExist};
  } else if (!get_single && !set_single) {
    o = {GeneralStatus::kServiceNotSupported};
  } else if (set_single && request.instance_id == 0) {
    o = {GeneralStatus::kServiceNotSupported};  // no Set at class level
  } else if (!request.attribute) {
    o = {GeneralStatus::kNotEnoughData};
  } else if (get_single && !request.data.empty()) {
    o = {GeneralStatus::kTooMuchData};
  } else {
    o = get_single ? get(request, w) : set(request);
  }
  if (o.status == GeneralStatus::kSuccess && !w.ok()) o = {GeneralStatus::kReplyDataTooLarge};
  if (o.status == GeneralStatus::kSuccess) {
    auto n = devicenet::encode_success_response(request.service, w.written(), out);
    if (n.ok()) return *n;
    o = {GeneralStatus::kReplyDataTooLarge};
  }
  auto n = devicenet::encode_error_response(o.status, o.additional, out);
  return n.ok() ? *n : 0;
}

}  // namespace dnbridge::sim
