#pragma once
// What dnbridge takes from an EDS file (eds_text.hpp reads its text):
//
//   [Device]    the identity a node is keyed and checked by: VendCode,
//               ProdType, ProdCode, MajRev, MinRev (required), VendName,
//               ProdTypeStr, ProdName, Catalog.
//   [IO_Info]   the I/O connections the device offers: Default (the kinds
//               used unless configured otherwise), PollInfo, StrobeInfo,
//               COSInfo, CyclicInfo (each: the kinds it combines with, its
//               input and its output by number, 0 for none), and the data
//               InputN / OutputN (size in bytes, bits used, the kinds that
//               carry it, name, path size, path, help).
//   [Params]    ParamN: link path size and path, descriptor, CIP data type
//               and size, name, units, help, minimum, maximum, default,
//               multiplier, divisor, base, offset, four scaling links,
//               decimal places.
//   [Assembly]  AssemN: name, path, size in bits, descriptor, two reserved
//               fields, then its members as pairs of size in bits and what
//               the bits are (a path, ParamN, AssemN, or nothing: padding).
//
// The connection kind bits are those of [IO_Info] (and of the Connection
// object's instances): 0x01 poll, 0x02 bit-strobe, 0x04 change of state,
// 0x08 cyclic. Other sections and keywords are ignored. Everything found
// wrong is a Problem on its line; an error makes the file unusable.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bridge/cip/epath.hpp"
#include "bridge/profiles/eds/eds_text.hpp"

namespace dnbridge::profiles::eds {

struct Device {
  std::uint16_t vendor_code = 0;
  std::string vendor_name;
  std::uint16_t product_type = 0;
  std::string product_type_name;
  std::uint16_t product_code = 0;
  std::uint8_t major_revision = 0;
  std::uint8_t minor_revision = 0;
  std::string product_name;
  std::string catalog;
};

enum class ConnectionKind : std::uint8_t {
  kPoll = 0x01,
  kStrobe = 0x02,
  kChangeOfState = 0x04,
  kCyclic = 0x08,
};
std::string_view to_string(ConnectionKind kind) noexcept;
inline constexpr ConnectionKind kConnectionKinds[] = {
    ConnectionKind::kPoll, ConnectionKind::kStrobe, ConnectionKind::kChangeOfState,
    ConnectionKind::kCyclic};

// A set of ConnectionKind bits.
struct ConnectionKinds {
  std::uint16_t bits = 0;
  bool has(ConnectionKind k) const noexcept { return (bits & static_cast<std::uint16_t>(k)) != 0; }
  friend bool operator==(ConnectionKinds, ConnectionKinds) = default;
};
// "poll, change of state"; "none" when empty.
std::string to_string(ConnectionKinds kinds);

// An InputN or OutputN of [IO_Info].
struct IoData {
  unsigned number = 0;
  std::uint16_t size = 0;       // bytes
  std::uint16_t bits_used = 0;  // 0: every bit of `size`
  ConnectionKinds carried_by;
  std::string name;
  cip::EPath path;  // to the data, usually an Assembly's attribute 3
  std::string help;
  std::uint32_t line = 0;
};

// PollInfo, StrobeInfo, COSInfo or CyclicInfo.
struct ConnectionInfo {
  ConnectionKind kind = ConnectionKind::kPoll;
  ConnectionKinds combines_with;
  unsigned input = 0;   // InputN's N; 0: none
  unsigned output = 0;  // OutputN's N; 0: none
  std::uint32_t line = 0;
};

struct IoInfo {
  ConnectionKinds defaults;
  std::vector<ConnectionInfo> connections;
  std::vector<IoData> inputs;
  std::vector<IoData> outputs;

  const ConnectionInfo* connection(ConnectionKind kind) const noexcept;
  const IoData* input(unsigned number) const noexcept;
  const IoData* output(unsigned number) const noexcept;
};

// The CIP elementary data types parameters are given in.
struct DataType {
  std::uint8_t code = 0;
  std::string_view name;
  std::uint8_t size = 0;  // bytes; 0: as long as the value (strings)
  bool is_signed = false;
  bool is_float = false;
};
// The type of `code` (0xC1 BOOL ... 0xDA SHORT_STRING); nullptr if unknown.
const DataType* data_type(std::uint8_t code) noexcept;

struct Param {
  unsigned number = 0;
  cip::EPath link;  // where the value lives on the device; empty: none
  std::uint16_t descriptor = 0;
  DataType type;
  std::uint16_t size = 0;  // bytes
  std::string name;
  std::string units;
  std::string help;
  std::optional<double> minimum, maximum, default_value;
  // Shown = (raw + offset) * multiplier * base / divisor, with
  // `decimals` places; multiplier, divisor and base default to 1.
  double multiplier = 1, divisor = 1, base = 1, offset = 0;
  unsigned decimals = 0;
  std::uint32_t line = 0;

  static constexpr std::uint16_t kReadOnly = 0x0010;  // descriptor bit 4
  bool read_only() const noexcept { return (descriptor & kReadOnly) != 0; }
};

// What an assembly member's bits are.
struct Member {
  enum class Kind : std::uint8_t { kPadding, kPath, kParam, kAssembly };
  std::uint16_t bits = 0;
  Kind kind = Kind::kPadding;
  cip::EPath path;      // kPath
  unsigned number = 0;  // kParam, kAssembly: ParamN's or AssemN's N
};

struct Assembly {
  unsigned number = 0;  // AssemN's N (by convention its instance)
  std::string name;
  cip::EPath path;
  std::optional<std::uint32_t> bits;  // the size given
  std::uint16_t descriptor = 0;
  std::vector<Member> members;
  std::uint32_t line = 0;

  // The size given, or its members' when none is.
  std::uint32_t size_bits() const noexcept {
    if (bits) return *bits;
    std::uint32_t total = 0;
    for (const auto& m : members) total += m.bits;
    return total;
  }
};

struct EdsFile {
  std::string description;  // [File] DescText
  std::string revision;     // [File] Revision
  Device device;
  IoInfo io;
  std::vector<Param> params;
  // The N of each ParamN entry left out (a warning says why, at its line):
  // an assembly member may still name it; its bits are then not read.
  std::vector<unsigned> params_left_out;
  std::vector<Assembly> assemblies;

  const Param* param(unsigned number) const noexcept;
  bool param_left_out(unsigned number) const noexcept;
  // The parameter `name` names: "ParamN", or a name (any case) no other
  // parameter has. nullptr when none does, or several (params_named()).
  const Param* param(std::string_view name) const noexcept;
  // The numbers of the parameters with this name (any case).
  std::vector<unsigned> params_named(std::string_view name) const;
  // The assembly an IoData's path leads to (its class 4 instance), if described.
  const Assembly* assembly_at(const cip::EPath& path) const noexcept;
};

// N of "ParamN" (any case); nothing for another name.
std::optional<unsigned> param_number(std::string_view name) noexcept;

struct Parsed {
  std::optional<EdsFile> file;  // absent when there is an error
                                // At most kMaxProblems, errors before warnings, in line order.
  std::vector<Problem> problems;
  std::size_t errors = 0;     // all of them, shown or not
  std::size_t not_shown = 0;  // problems past kMaxProblems
};

// Reads `text` (the whole file).
Parsed parse(std::string_view text);

// "FILE:LINE: error: MESSAGE" (or warning), as compilers write them.
std::string format_problem(std::string_view file, const Problem& problem);

}  // namespace dnbridge::profiles::eds
