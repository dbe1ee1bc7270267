#include "bridge/profiles/eds/member_check.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <optional>

namespace dnbridge::profiles::eds {
namespace {

// What an EDS member should be on the device: padding (an empty path), a
// path, or unknown (compared by size only).
struct Expected {
  bool padding = false;
  std::optional<cip::EPath> path;
  std::string text;
};

Expected expected_of(const EdsFile& file, const Member& m) {
  switch (m.kind) {
    case Member::Kind::kPadding:
      return {true, std::nullopt, "padding"};
    case Member::Kind::kPath:
      return {false, m.path, cip::describe(m.path)};
    case Member::Kind::kParam: {
      const Param* p = file.param(m.number);
      if (p != nullptr && !p->link.empty()) {
        return {false, p->link,
                fmt::format("Param{} ({}), {}", m.number, p->name, cip::describe(p->link))};
      }
      return {false, std::nullopt, fmt::format("Param{}", m.number)};
    }
    case Member::Kind::kAssembly:
      return {false, std::nullopt, fmt::format("Assem{}", m.number)};
  }
  return {};
}

}  // namespace

std::vector<std::string> member_differences(const EdsFile& file, const Assembly& expected,
                                            const std::vector<cip::AssemblyMember>& reported) {
  std::vector<std::string> out;
  if (!expected.bits && expected.members.empty()) return out;  // the EDS says nothing of it
  const std::uint32_t expected_bits = expected.size_bits();
  const std::uint32_t reported_bits = cip::member_bits(reported);
  if (expected_bits != reported_bits) {
    out.push_back(fmt::format("{} bits in all on the device, {} in the EDS (Assem{})",
                              reported_bits, expected_bits, expected.number));
  }
  if (expected.members.empty()) return out;  // the EDS describes no members
  if (expected.members.size() != reported.size()) {
    out.push_back(fmt::format("{} members on the device, {} in the EDS (Assem{})", reported.size(),
                              expected.members.size(), expected.number));
  }
  const std::size_t n = std::min(expected.members.size(), reported.size());
  for (std::size_t i = 0; i < n; ++i) {
    const Member& e = expected.members[i];
    const cip::AssemblyMember& r = reported[i];
    const Expected want = expected_of(file, e);
    if (e.bits != r.bits) {
      out.push_back(fmt::format("member {}: {} bits on the device, {} in the EDS ({})", i + 1,
                                r.bits, e.bits, want.text));
    }
    const bool same_kind = want.padding == r.padding();
    const bool same_path = !want.path || (r.path && *r.path == *want.path);
    if (!same_kind || !same_path) {
      out.push_back(fmt::format("member {}: {} on the device, {} in the EDS", i + 1,
                                cip::describe_path(r), want.text));
    }
  }
  return out;
}

}  // namespace dnbridge::profiles::eds
