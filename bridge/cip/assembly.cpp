#include "bridge/cip/assembly.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace dnbridge::cip {

Result<std::vector<AssemblyMember>> decode_member_list(Bytes data) {
  ByteReader reader(data);
  std::vector<AssemblyMember> members;
  while (reader.remaining() > 0) {
    if (members.size() == kMaxAssemblyMembers) return make_error_code(Errc::kMalformed);
    AssemblyMember m;
    m.bits = reader.u16le();
    const std::uint16_t path_size = reader.u16le();
    const Bytes path = reader.bytes(path_size);
    if (!reader.ok()) return make_error_code(Errc::kTruncated);
    m.path_bytes.assign(path.begin(), path.end());
    if (!path.empty()) {
      if (auto decoded = decode_epath(path)) m.path = *decoded;
    }
    members.push_back(std::move(m));
  }
  return members;
}

std::vector<std::uint8_t> encode_member_list(const std::vector<AssemblyMember>& members) {
  std::vector<std::uint8_t> out;
  for (const auto& m : members) {
    const auto size = static_cast<std::uint16_t>(m.path_bytes.size());
    out.push_back(static_cast<std::uint8_t>(m.bits & 0xFF));
    out.push_back(static_cast<std::uint8_t>(m.bits >> 8));
    out.push_back(static_cast<std::uint8_t>(size & 0xFF));
    out.push_back(static_cast<std::uint8_t>(size >> 8));
    out.insert(out.end(), m.path_bytes.begin(), m.path_bytes.end());
  }
  return out;
}

std::uint32_t member_bits(const std::vector<AssemblyMember>& members) noexcept {
  std::uint32_t bits = 0;
  for (const auto& m : members) bits += m.bits;
  return bits;
}

std::string describe(const EPath& path) {
  if (path.empty()) return "(empty)";
  std::string out;
  const auto part = [&](std::string_view name, const std::optional<std::uint32_t>& v) {
    if (!v) return;
    if (!out.empty()) out += ' ';
    out += fmt::format("{} 0x{:02X}", name, *v);
  };
  part("class", path.class_id);
  part("instance", path.instance_id);
  part("connection point", path.connection_point);
  part("attribute", path.attribute);
  return out;
}

std::string describe_path(const AssemblyMember& member) {
  if (member.padding()) return "padding";
  if (member.path) return describe(*member.path);
  return fmt::format("path {:02X}", fmt::join(member.path_bytes, " "));
}

std::string describe(const AssemblyMember& member) {
  return fmt::format("{} {}: {}", member.bits, member.bits == 1 ? "bit" : "bits",
                     describe_path(member));
}

}  // namespace dnbridge::cip
