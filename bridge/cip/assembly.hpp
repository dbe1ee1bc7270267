#pragma once
// What an Assembly object instance (class 0x04) says of itself, as the
// 1203-CN1 manual gives the object (shared/seeds/003):
//   class attribute 1 Revision (UINT), 2 Max Instance (UINT);
//   instance attribute 1 Number of Members in List (UINT);
//   2 Member List: per member, Member Data Size (UINT, in bits), Member
//     Path Size (UINT, in bytes; 0 = an empty path) and Member Path;
//   3 Data: every member's data packed into one array, members with an
//     empty path being padding (to keep data on word boundaries).
// Member paths are decoded where they are logical paths (cip/epath.hpp);
// others are kept as their bytes.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bridge/cip/epath.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"

namespace dnbridge::cip {

struct AssemblyMember {
  std::uint16_t bits = 0;
  std::vector<std::uint8_t> path_bytes;  // as the device sent them
  std::optional<EPath> path;             // when the bytes are a logical path

  bool padding() const noexcept { return path_bytes.empty(); }
  friend bool operator==(const AssemblyMember&, const AssemblyMember&) = default;
};

// Attribute 2 as the device sends it (no count first: attribute 1 has it).
// kTruncated when a member's sizes or path are cut off. At most
// kMaxAssemblyMembers members (an attribute of at most 64 KiB cannot hold
// more than 16 384 of 4 bytes each).
inline constexpr std::size_t kMaxAssemblyMembers = 16384;
Result<std::vector<AssemblyMember>> decode_member_list(Bytes data);

// Encodes `members` as attribute 2 (what a device sends); the bytes.
std::vector<std::uint8_t> encode_member_list(const std::vector<AssemblyMember>& members);

// The bits of all members.
std::uint32_t member_bits(const std::vector<AssemblyMember>& members) noexcept;

// "class 0x0F instance 0x02 attribute 0x01" (a logical path), "(empty)".
std::string describe(const EPath& path);
// What a member is: "class 0x0F instance 0x02 attribute 0x01", "padding",
// "path 91 03 41 42 43 00" (one that is not a logical path).
std::string describe_path(const AssemblyMember& member);
// With its size: "16 bits: class 0x0F instance 0x02 attribute 0x01".
std::string describe(const AssemblyMember& member);

}  // namespace dnbridge::cip
