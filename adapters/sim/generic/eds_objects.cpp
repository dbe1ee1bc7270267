#include "adapters/sim/generic/eds_objects.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <optional>

#include "bridge/cip/assembly.hpp"
#include "bridge/cip/data_types.hpp"
#include "bridge/cip/objects.hpp"
#include "bridge/cip/service.hpp"

namespace dnbridge::sim {
namespace {

using cip::GeneralStatus;

constexpr std::uint16_t kParameterClass = 0x0F;
constexpr std::uint16_t kAckHandlerClass = 0x2B;

// A parameter's value as bytes (little-endian, its data size) from a number.
std::vector<std::uint8_t> encode_value(const eds::Param& p, double v) {
  std::vector<std::uint8_t> out(p.size, 0);
  if (p.type.is_float) {
    if (p.size == 4) {
      const auto bits = std::bit_cast<std::uint32_t>(static_cast<float>(v));
      for (std::size_t i = 0; i < 4; ++i) out[i] = static_cast<std::uint8_t>(bits >> (8 * i));
    } else if (p.size == 8) {
      const auto bits = std::bit_cast<std::uint64_t>(v);
      for (std::size_t i = 0; i < 8; ++i) out[i] = static_cast<std::uint8_t>(bits >> (8 * i));
    }
    return out;
  }
  if (p.type.size == 0) return out;  // strings: no value kept
  const auto bits = static_cast<std::uint64_t>(static_cast<std::int64_t>(v));
  for (std::size_t i = 0; i < out.size() && i < 8; ++i) {
    out[i] = static_cast<std::uint8_t>(bits >> (8 * i));
  }
  return out;
}

// The number `value` holds, as its type reads it.
std::optional<double> decode_value(const eds::Param& p, Bytes value) {
  if (value.size() != p.size || p.type.size == 0) return std::nullopt;
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < value.size() && i < 8; ++i) {
    bits |= static_cast<std::uint64_t>(value[i]) << (8 * i);
  }
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

EdsObjects::EdsObjects(eds::EdsFile file, std::uint32_t serial_number)
    : file_(std::move(file)), serial_number_(serial_number) {
  for (const auto& p : file_.params) {
    values_[p.number] = encode_value(p, p.default_value.value_or(0.0));
  }
}

std::vector<std::uint8_t> EdsObjects::param_value(unsigned number) const {
  auto it = values_.find(number);
  return it == values_.end() ? std::vector<std::uint8_t>{} : it->second;
}

bool EdsObjects::set_param_value(unsigned number, Bytes value) {
  auto it = values_.find(number);
  if (it == values_.end() || it->second.size() != value.size()) return false;
  it->second.assign(value.begin(), value.end());
  return true;
}

const eds::Assembly* EdsObjects::assembly(unsigned number) const noexcept {
  for (const auto& a : file_.assemblies) {
    if (a.number == number) return &a;
  }
  return nullptr;
}

std::vector<std::uint8_t> EdsObjects::assembly_data(unsigned number) const {
  const eds::Assembly* a = assembly(number);
  if (a == nullptr) return {};
  const std::uint32_t total = a->size_bits();
  std::vector<std::uint8_t> out((total + 7) / 8, 0);
  std::uint32_t at = 0;
  const auto put = [&](const std::vector<std::uint8_t>& from, std::uint32_t bits) {
    for (std::uint32_t i = 0; i < bits && i / 8 < from.size() && at + i < total; ++i) {
      if ((from[i / 8] >> (i % 8)) & 1u) {
        out[(at + i) / 8] = static_cast<std::uint8_t>(out[(at + i) / 8] | (1u << ((at + i) % 8)));
      }
    }
  };
  for (const auto& m : a->members) {
    if (m.kind == eds::Member::Kind::kParam) put(param_value(m.number), m.bits);
    // A nested assembly once (an assembly naming itself reads as zeros).
    if (m.kind == eds::Member::Kind::kAssembly && m.number != number) {
      put(assembly_data(m.number), m.bits);
    }
    at += m.bits;
  }
  return out;
}

std::vector<cip::AssemblyMember> EdsObjects::member_list(const eds::Assembly& a) const {
  std::vector<cip::AssemblyMember> list;
  for (const auto& m : a.members) {
    cip::AssemblyMember out;
    out.bits = m.bits;
    std::optional<cip::EPath> path;
    switch (m.kind) {
      case eds::Member::Kind::kPadding:
        break;
      case eds::Member::Kind::kPath:
        path = m.path;
        break;
      case eds::Member::Kind::kParam: {
        const eds::Param* p = file_.param(m.number);
        path = p != nullptr && !p->link.empty()
                   ? p->link
                   : cip::EPath{kParameterClass, m.number, std::nullopt, 1};
        break;
      }
      case eds::Member::Kind::kAssembly: {
        const eds::Assembly* nested = assembly(m.number);
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
      const std::string_view name = std::string_view(d.product_name).substr(0, 255);
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
    unsigned max = 0;
    for (const auto& a : file_.assemblies) max = std::max(max, a.number);
    if (attribute == cip::class_attr::kRevision) {
      out.u16le(2);
    } else if (attribute == cip::class_attr::kMaxInstance) {
      out.u16le(static_cast<std::uint16_t>(max));
    } else {
      return {GeneralStatus::kAttributeNotSupported};
    }
    return {};
  }
  const eds::Assembly* a = assembly(instance);
  if (a == nullptr) return {GeneralStatus::kObjectDoesNotExist};
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
  if (file_.param(instance) == nullptr) return {GeneralStatus::kObjectDoesNotExist};
  if (attribute != 1) return {GeneralStatus::kAttributeNotSupported};
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
  const std::uint8_t attribute = r.attribute.value_or(0);
  switch (r.class_id) {
    case cip::class_id::kIdentity:
      if (r.instance_id != 1) return {GeneralStatus::kObjectDoesNotExist};
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

EdsObjects::Outcome EdsObjects::set(const devicenet::RequestMessage& r) {
  const std::uint8_t attribute = r.attribute.value_or(0);
  const auto size_check = [&](std::size_t want) -> std::optional<Outcome> {
    if (r.data.size() < want) return Outcome{GeneralStatus::kNotEnoughData};
    if (r.data.size() > want) return Outcome{GeneralStatus::kTooMuchData};
    return std::nullopt;
  };
  if (r.class_id == kParameterClass && r.instance_id != 0) {
    const eds::Param* p = file_.param(r.instance_id);
    if (p == nullptr) return {GeneralStatus::kObjectDoesNotExist};
    if (attribute != 1) return {GeneralStatus::kAttributeNotSettable};
    if (p->read_only()) return {GeneralStatus::kAttributeNotSettable};
    if (auto bad = size_check(p->size)) return *bad;
    const auto v = decode_value(*p, r.data);
    if (!v || (p->minimum && *v < *p->minimum) || (p->maximum && *v > *p->maximum)) {
      return {GeneralStatus::kInvalidAttributeValue};
    }
    values_[p->number].assign(r.data.begin(), r.data.end());
    return {};
  }
  if (r.class_id == kAckHandlerClass && r.instance_id == 1) {
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
      case 3:
        if (auto bad = size_check(2)) return *bad;
        ack_.cos_producing_instance = static_cast<std::uint16_t>(r.data[0] | r.data[1] << 8);
        return {};
      case 4:
      case 5:
        return {GeneralStatus::kAttributeNotSettable};
      default:
        return {GeneralStatus::kAttributeNotSupported};
    }
  }
  // Identity, Assembly and the class attributes: read only here.
  ByteWriter probe(MutableBytes{});
  const Outcome exists = get(r, probe);
  if (exists.status == GeneralStatus::kObjectDoesNotExist ||
      exists.status == GeneralStatus::kAttributeNotSupported) {
    return exists;
  }
  return {GeneralStatus::kAttributeNotSettable};
}

std::size_t EdsObjects::execute(const devicenet::RequestMessage& request, MutableBytes out) {
  std::array<std::uint8_t, devicenet::kMaxExplicitMessage> data{};
  ByteWriter w{MutableBytes(data)};
  Outcome o;
  const auto service = static_cast<cip::Service>(request.service);
  if (service == cip::Service::kGetAttributeSingle) {
    o = get(request, w);
  } else if (service == cip::Service::kSetAttributeSingle) {
    o = set(request);
  } else {
    o = {GeneralStatus::kServiceNotSupported};
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
