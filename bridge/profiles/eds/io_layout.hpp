#pragma once
// The named, typed fields of an I/O connection's data, as the EDS describes
// them: the InputN or OutputN names its data by path, the [Assembly] entry
// at that path lists the members, least significant bit of the first byte
// first (shared/seeds/003: members packed into one array, empty paths being
// padding). A ParamN member is a field with the parameter's name, type,
// units and scaling; a path member is a field of raw bits named by its
// path; an AssemN member is unfolded into its own members; padding is no
// field. Data whose path names no described assembly has no fields: its
// bytes are all there is.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"
#include "bridge/profiles/eds/eds_file.hpp"

namespace dnbridge::profiles::eds {

struct IoField {
  std::string name;   // the parameter's; a path member: its path described
  std::string units;  // the parameter's; empty for a path member
  // The parameter's type; a path member's has code 0 and name "bits": an
  // unsigned number of its bits.
  DataType type;
  std::uint32_t offset = 0;  // first bit, from the data's first byte's bit 0
  std::uint16_t bits = 0;
  // Numbers only: a field of a string type, a REAL that is not 32 bits or
  // an LREAL that is not 64, or more than 64 bits, is skipped by decode()
  // and refused by encode().
  bool numeric = false;
  // The parameter's, when the field is one (EDS limits; shown value =
  // (value + offset) * multiplier * base / divisor).
  std::optional<double> minimum, maximum;
  double multiplier = 1, divisor = 1, base = 1, scale_offset = 0;
  unsigned param = 0;  // ParamN's N; 0 for a path member
};

struct IoLayout {
  std::uint16_t size = 0;  // the data's bytes (InputN/OutputN size)
  std::string name;        // InputN/OutputN's name
  std::string assembly;    // "Assem100 (Inputs and status)"; empty: no fields known
  std::vector<IoField> fields;

  // The field `name` names: "ParamN" (its parameter's), or a name (any case)
  // no other field has; nullptr when none does, or several.
  const IoField* field(std::string_view name) const noexcept;
  std::size_t fields_named(std::string_view name) const noexcept;
};

// The layout of `data` (an InputN or OutputN of `file`).
IoLayout layout_of(const EdsFile& file, const IoData& data);

// A number as a field of `type` in `bits` holds it: its raw bits, or
// nothing when it does not fit (not an integer of an integer type, beyond
// the range of the type or of the bits, not finite). `bits` at most 64.
std::optional<std::uint64_t> to_raw(const DataType& type, std::uint16_t bits, double value);
// The number `raw` (the low `bits` bits) is, read as `type`.
double from_raw(const DataType& type, std::uint16_t bits, std::uint64_t raw);

// Whether `value` is within the EDS's limits (either may be absent), and
// the limits as "MIN..MAX" ("-inf" or "inf" for an absent one).
bool within_limits(const std::optional<double>& minimum, const std::optional<double>& maximum,
                   double value) noexcept;
std::string limits_text(const std::optional<double>& minimum, const std::optional<double>& maximum);

struct FieldValue {
  std::size_t field = 0;  // index in IoLayout::fields
  std::uint64_t raw = 0;  // its bits as they are in the data
  double value = 0;       // as its type reads them (signed, REAL, ...)
  double shown = 0;       // with the EDS's scaling, in its units
};

// The numeric fields of `data`, in layout order; a field beyond the bytes
// given is left out.
std::vector<FieldValue> decode(const IoLayout& layout, Bytes data);

// A field's value as a command gives it: by name, as its type reads it
// (not scaled).
struct FieldSetting {
  std::string name;
  double value = 0;
};

// The data for `settings`: every numeric field must be given once, within
// its type's range and its bits and the EDS's limits; padding is zero.
// kMalformed for a field missing, unknown, given twice or not a number,
// kOutOfRange for a value that does not fit; `why` says which and what.
Result<std::vector<std::uint8_t>> encode(const IoLayout& layout,
                                         const std::vector<FieldSetting>& settings,
                                         std::string* why = nullptr);

// Whether `data` may be sent as the layout's data: its size, and every
// numeric field a finite number within the EDS's limits. kMalformed for
// another size, kOutOfRange for a field, `why` saying which and what.
Status check(const IoLayout& layout, Bytes data, std::string* why = nullptr);

}  // namespace dnbridge::profiles::eds
