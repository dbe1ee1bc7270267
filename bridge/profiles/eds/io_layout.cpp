#include "bridge/profiles/eds/io_layout.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "bridge/cip/assembly.hpp"
#include "bridge/common/text.hpp"

namespace dnbridge::profiles::eds {
namespace {

constexpr DataType kBits{0, "bits", 0, false, false};

// How deep nested assemblies are unfolded (the reader refuses cycles; this
// bounds what it accepts).
constexpr unsigned kMaxNesting = 8;

// The bits of an integer of `type` in a field of `bits`: the field's, or
// the type's when it has fewer.
unsigned value_bits(const DataType& type, std::uint16_t bits) noexcept {
  const unsigned type_bits = type.size == 0 ? 64U : type.size * 8U;
  return std::min<unsigned>(bits, type_bits);
}

bool is_numeric(const DataType& type, std::uint16_t bits) noexcept {
  if (bits == 0 || bits > 64) return false;
  if (type.code == 0) return true;   // raw bits
  if (type.size == 0) return false;  // strings
  if (type.is_float) return bits == type.size * 8;
  return true;
}

class Unfolder {
 public:
  Unfolder(const EdsFile& file, IoLayout& layout) : file_(file), layout_(layout) {}

  void unfold(const Assembly& assembly, unsigned depth) {
    if (depth > kMaxNesting) return;
    for (const Member& m : assembly.members) {
      switch (m.kind) {
        case Member::Kind::kPadding:
          break;
        case Member::Kind::kParam:
          add_param(m);
          break;
        case Member::Kind::kPath:
          add_path(m);
          break;
        case Member::Kind::kAssembly:
          if (const Assembly* inner = numbered(m.number)) {
            const std::uint32_t start = offset_;
            unfold(*inner, depth + 1);
            offset_ = start;  // the member's own size counts, as packed
          }
          break;
      }
      offset_ += m.bits;
    }
  }

 private:
  const Assembly* numbered(unsigned number) const noexcept {
    for (const auto& a : file_.assemblies) {
      if (a.number == number) return &a;
    }
    return nullptr;
  }

  void add_param(const Member& m) {
    const Param* p = file_.param(m.number);
    if (p == nullptr) return;  // the reader reports it
    IoField f;
    f.name = p->name;
    f.units = p->units;
    f.type = p->type;
    f.offset = offset_;
    f.bits = m.bits;
    f.numeric = is_numeric(p->type, m.bits);
    f.minimum = p->minimum;
    f.maximum = p->maximum;
    f.multiplier = p->multiplier;
    f.divisor = p->divisor;
    f.base = p->base;
    f.scale_offset = p->offset;
    f.param = p->number;
    layout_.fields.push_back(std::move(f));
  }

  void add_path(const Member& m) {
    IoField f;
    f.name = cip::describe(m.path);
    f.type = kBits;
    f.offset = offset_;
    f.bits = m.bits;
    f.numeric = is_numeric(kBits, m.bits);
    layout_.fields.push_back(std::move(f));
  }

  const EdsFile& file_;
  IoLayout& layout_;
  std::uint32_t offset_ = 0;
};

std::uint64_t read_bits(Bytes data, std::uint32_t offset, std::uint16_t bits) noexcept {
  std::uint64_t raw = 0;
  for (unsigned i = 0; i < bits; ++i) {
    const std::uint32_t at = offset + i;
    if (((static_cast<unsigned>(data[at / 8]) >> (at % 8)) & 1U) != 0) raw |= std::uint64_t{1} << i;
  }
  return raw;
}

void write_bits(std::vector<std::uint8_t>& data, std::uint32_t offset, std::uint16_t bits,
                std::uint64_t raw) noexcept {
  for (unsigned i = 0; i < bits; ++i) {
    const std::uint32_t at = offset + i;
    const auto mask = static_cast<std::uint8_t>(1U << (at % 8));
    if (((raw >> i) & 1U) != 0) {
      data[at / 8] = static_cast<std::uint8_t>(data[at / 8] | mask);
    } else {
      data[at / 8] = static_cast<std::uint8_t>(data[at / 8] & ~mask);
    }
  }
}

// "NAME: VALUE is outside MIN..MAX" when `value` is beyond the field's EDS limits.
std::optional<std::string> beyond_limits(const IoField& f, double value) {
  if (within_limits(f.minimum, f.maximum, value)) return std::nullopt;
  return fmt::format("{}: {} is outside {}", f.name, value, limits_text(f.minimum, f.maximum));
}

}  // namespace

bool within_limits(const std::optional<double>& minimum, const std::optional<double>& maximum,
                   double value) noexcept {
  return !((minimum && value < *minimum) || (maximum && value > *maximum));
}

std::string limits_text(const std::optional<double>& minimum,
                        const std::optional<double>& maximum) {
  return fmt::format("{}..{}", minimum.value_or(-INFINITY), maximum.value_or(INFINITY));
}

const IoField* IoLayout::field(std::string_view wanted) const noexcept {
  if (auto n = param_number(wanted)) {
    for (const auto& f : fields) {
      if (f.param == *n) return &f;
    }
    return nullptr;
  }
  const IoField* found = nullptr;
  for (const auto& f : fields) {
    if (!iequals(f.name, wanted)) continue;
    if (found != nullptr) return nullptr;  // several
    found = &f;
  }
  return found;
}

std::size_t IoLayout::fields_named(std::string_view wanted) const noexcept {
  return static_cast<std::size_t>(std::count_if(
      fields.begin(), fields.end(), [&](const IoField& f) { return iequals(f.name, wanted); }));
}

IoLayout layout_of(const EdsFile& file, const IoData& data) {
  IoLayout layout;
  layout.size = data.size;
  layout.name = data.name;
  if (const Assembly* a = file.assembly_at(data.path)) {
    layout.assembly = a->name.empty() ? fmt::format("Assem{}", a->number)
                                      : fmt::format("Assem{} ({})", a->number, a->name);
    Unfolder(file, layout).unfold(*a, 0);
  }
  return layout;
}

std::optional<std::uint64_t> to_raw(const DataType& type, std::uint16_t bits, double value) {
  if (!std::isfinite(value) || bits == 0 || bits > 64) return std::nullopt;
  if (type.is_float) {
    if (type.size == 4) {
      if (bits != 32 || std::abs(value) > std::numeric_limits<float>::max()) return std::nullopt;
      return std::bit_cast<std::uint32_t>(static_cast<float>(value));
    }
    if (bits != 64) return std::nullopt;
    return std::bit_cast<std::uint64_t>(value);
  }
  if (std::floor(value) != value) return std::nullopt;
  const unsigned n = value_bits(type, bits);
  // [lo, end): exact in a double for every n up to 64, where 2^64 - 1 is not.
  const double lo = type.is_signed ? -std::ldexp(1.0, static_cast<int>(n) - 1) : 0.0;
  const double end = std::ldexp(1.0, static_cast<int>(n) - (type.is_signed ? 1 : 0));
  if (value < lo || value >= end) return std::nullopt;
  if (type.is_signed) {
    const auto v = static_cast<std::int64_t>(value);
    const std::uint64_t mask = n == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << n) - 1;
    return static_cast<std::uint64_t>(v) & mask;
  }
  return static_cast<std::uint64_t>(value);
}

double from_raw(const DataType& type, std::uint16_t bits, std::uint64_t raw) {
  if (type.is_float) {
    if (type.size == 4) return std::bit_cast<float>(static_cast<std::uint32_t>(raw));
    return std::bit_cast<double>(raw);
  }
  const unsigned n = value_bits(type, bits);
  if (n < 64) raw &= (std::uint64_t{1} << n) - 1;
  if (type.is_signed && n > 0 && n < 64 && ((raw >> (n - 1)) & 1U) != 0) {
    raw |= ~std::uint64_t{0} << n;  // sign-extended
  }
  if (type.is_signed) return static_cast<double>(static_cast<std::int64_t>(raw));
  return static_cast<double>(raw);
}

std::vector<FieldValue> decode(const IoLayout& layout, Bytes data) {
  std::vector<FieldValue> values;
  const std::uint64_t have_bits = std::uint64_t{data.size()} * 8;
  for (std::size_t i = 0; i < layout.fields.size(); ++i) {
    const IoField& f = layout.fields[i];
    if (!f.numeric || std::uint64_t{f.offset} + f.bits > have_bits) continue;
    FieldValue v;
    v.field = i;
    v.raw = read_bits(data, f.offset, f.bits);
    v.value = from_raw(f.type, f.bits, v.raw);
    v.shown = (v.value + f.scale_offset) * f.multiplier * f.base / f.divisor;
    values.push_back(v);
  }
  return values;
}

Result<std::vector<std::uint8_t>> encode(const IoLayout& layout,
                                         const std::vector<FieldSetting>& settings,
                                         std::string* why) {
  const auto fail = [&](Errc code, std::string text) -> Result<std::vector<std::uint8_t>> {
    if (why != nullptr) *why = std::move(text);
    return code;
  };
  std::vector<std::uint8_t> data(layout.size, 0);
  std::vector<bool> given(layout.fields.size(), false);
  for (const FieldSetting& s : settings) {
    const IoField* f = layout.field(s.name);
    if (f == nullptr) {
      if (const std::size_t n = layout.fields_named(s.name); n > 1) {
        return fail(Errc::kMalformed,
                    fmt::format("\"{}\" names {} fields: name one as ParamN", s.name, n));
      }
      return fail(Errc::kMalformed, fmt::format("no field \"{}\"", s.name));
    }
    const auto index = static_cast<std::size_t>(f - layout.fields.data());
    if (given[index]) return fail(Errc::kMalformed, fmt::format("{} is given twice", f->name));
    given[index] = true;
    if (!f->numeric) {
      return fail(Errc::kMalformed,
                  fmt::format("{} ({}, {} bits) is not a number", f->name, f->type.name, f->bits));
    }
    if (auto outside = beyond_limits(*f, s.value)) return fail(Errc::kOutOfRange, *outside);
    auto raw = to_raw(f->type, f->bits, s.value);
    if (!raw) {
      return fail(Errc::kOutOfRange, fmt::format("{}: {} is not a {} of {} bits", f->name, s.value,
                                                 f->type.name, f->bits));
    }
    // The limits hold for the value as sent, too (a REAL in single precision).
    if (auto outside = beyond_limits(*f, from_raw(f->type, f->bits, *raw))) {
      return fail(Errc::kOutOfRange, *outside);
    }
    if (std::uint64_t{f->offset} + f->bits > std::uint64_t{layout.size} * 8) {
      return fail(Errc::kOutOfRange,
                  fmt::format("{}: bits {}..{} are beyond the {} bytes of {}", f->name, f->offset,
                              f->offset + f->bits - 1, layout.size, layout.name));
    }
    write_bits(data, f->offset, f->bits, *raw);
  }
  for (std::size_t i = 0; i < layout.fields.size(); ++i) {
    if (layout.fields[i].numeric && !given[i]) {
      return fail(Errc::kMalformed, fmt::format("{} is not given", layout.fields[i].name));
    }
  }
  return data;
}

Status check(const IoLayout& layout, Bytes data, std::string* why) {
  const auto fail = [&](Errc code, std::string text) -> Status {
    if (why != nullptr) *why = std::move(text);
    return code;
  };
  if (data.size() != layout.size) {
    return fail(Errc::kMalformed, fmt::format("{} bytes given, \"{}\" is {} bytes", data.size(),
                                              layout.name, layout.size));
  }
  // Where the EDS describes the data, what it leaves undescribed (padding,
  // fields that are not numbers) must be zero, as encode() leaves it.
  if (!layout.fields.empty()) {
    std::vector<bool> covered(data.size() * 8, false);
    for (const IoField& f : layout.fields) {
      if (!f.numeric) continue;
      for (std::uint32_t b = f.offset; b < f.offset + f.bits && b < covered.size(); ++b) {
        covered[b] = true;
      }
    }
    for (std::size_t b = 0; b < covered.size(); ++b) {
      if (!covered[b] && ((static_cast<unsigned>(data[b / 8]) >> (b % 8)) & 1U) != 0) {
        return fail(Errc::kOutOfRange,
                    fmt::format("bit {} of byte {} is set, and the EDS gives it no field (padding, "
                                "or a field that is not a number): it must be 0",
                                b % 8, b / 8));
      }
    }
  }
  for (const FieldValue& v : decode(layout, data)) {
    const IoField& f = layout.fields[v.field];
    if (!std::isfinite(v.value)) {
      return fail(Errc::kOutOfRange, fmt::format("{}: not a finite number", f.name));
    }
    if (auto outside = beyond_limits(f, v.value)) return fail(Errc::kOutOfRange, *outside);
  }
  return {};
}

}  // namespace dnbridge::profiles::eds
