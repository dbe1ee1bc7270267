// Reader: a ParamN of [Params] and an AssemN of [Assembly], each checked on
// its own.
#include <fmt/format.h>

#include <cmath>
#include <utility>

#include "bridge/profiles/eds/eds_file_internal.hpp"
#include "bridge/profiles/eds/io_layout.hpp"

namespace dnbridge::profiles::eds::eds_file_detail {

std::optional<Param> Reader::param(const Entry& e, unsigned number) {
  Param p;
  p.number = number;
  p.line = e.line;
  // Field 1 is reserved (0, or the data placeholder of old files).
  auto link_size = integer(e, 1, "link path size", 0, 0xFF);
  std::optional<cip::EPath> link;
  if (link_size) {
    if (*link_size == 0 && given(e, 2) == nullptr) {
      link = cip::EPath{};
    } else {
      link = path(e, 2, "link path", *link_size);
    }
  }
  auto descriptor = integer(e, 3, "descriptor", 0, 0xFFFF);
  auto type_code = integer(e, 4, "data type", 0, 0xFF);
  auto size = integer(e, 5, "data size", 0, 0xFFFF);
  p.name = string(e, 6);
  p.units = string(e, 7);
  p.help = string(e, 8);
  p.minimum = real(e, 9, "minimum");
  p.maximum = real(e, 10, "maximum");
  p.default_value = real(e, 11, "default");
  const auto factor = [&](std::size_t i, std::string_view what, double fallback) {
    return real(e, i, what).value_or(fallback);
  };
  p.multiplier = factor(12, "multiplier", 1);
  p.divisor = factor(13, "divisor", 1);
  p.base = factor(14, "base", 1);
  p.offset = factor(15, "offset", 0);
  // Fields 16..19: the scaling links, not read.
  if (given(e, 20) != nullptr) {
    if (auto d = integer(e, 20, "decimal places", 0, 15)) p.decimals = static_cast<unsigned>(*d);
  }
  if (!link || !descriptor || !type_code || !size) return std::nullopt;
  if (p.name.empty()) {
    error(e.line, fmt::format("{} has no name (field 7)", e.keyword));
    return std::nullopt;
  }
  p.link = *link;
  p.descriptor = static_cast<std::uint16_t>(*descriptor);
  p.size = static_cast<std::uint16_t>(*size);
  const DataType* type = data_type(static_cast<std::uint8_t>(*type_code));
  if (type == nullptr) {
    warning(e.line, fmt::format("{} ({}): data type 0x{:02X} is not one dnbridge reads; the "
                                "parameter is left out",
                                e.keyword, p.name, *type_code));
    return std::nullopt;
  }
  p.type = *type;
  if (type->size != 0 && p.size != type->size) {
    error(e.line, fmt::format("{} ({}): data size {} is not that of {} ({})", e.keyword, p.name,
                              p.size, type->name, type->size));
    return std::nullopt;
  }
  if (p.divisor == 0) {
    error(e.line, fmt::format("{} ({}): divisor 0", e.keyword, p.name));
    return std::nullopt;
  }
  if (p.minimum && p.maximum && *p.minimum > *p.maximum) {
    error(e.line, fmt::format("{} ({}): minimum {} is above maximum {}", e.keyword, p.name,
                              *p.minimum, *p.maximum));
    return std::nullopt;
  }
  if (p.default_value && ((p.minimum && *p.default_value < *p.minimum) ||
                          (p.maximum && *p.default_value > *p.maximum))) {
    error(e.line,
          fmt::format("{} ({}): default {} is outside {}..{}", e.keyword, p.name, *p.default_value,
                      p.minimum.value_or(-INFINITY), p.maximum.value_or(INFINITY)));
    return std::nullopt;
  }
  if (type->size != 0) {
    const auto bits = static_cast<std::uint16_t>(type->size * 8);
    for (auto [value, what] : {std::pair{p.minimum, "minimum"}, std::pair{p.maximum, "maximum"},
                               std::pair{p.default_value, "default"}}) {
      if (value && !to_raw(*type, bits, *value)) {
        error(e.line, fmt::format("{} ({}): {} {} is not a {} value", e.keyword, p.name, what,
                                  *value, type->name));
        return std::nullopt;
      }
    }
  }
  return p;
}

std::optional<Assembly> Reader::assembly(const Entry& e, unsigned number) {
  Assembly a;
  a.number = number;
  a.line = e.line;
  a.name = string(e, 0);
  if (given(e, 1) != nullptr && !e.fields[1].text.empty()) {
    auto p = path(e, 1, "path");
    if (!p) return std::nullopt;
    a.path = *p;
  } else {
    a.path.class_id = 4;
    a.path.instance_id = number;
    a.path.attribute = 3;
  }
  if (given(e, 2) != nullptr) {
    auto bits = integer(e, 2, "size in bits", 0, std::int64_t{0xFFFF} * 8);
    if (!bits) return std::nullopt;
    a.bits = static_cast<std::uint32_t>(*bits);
  }
  if (given(e, 3) != nullptr) {
    auto d = integer(e, 3, "descriptor", 0, 0xFFFF);
    if (!d) return std::nullopt;
    a.descriptor = static_cast<std::uint16_t>(*d);
  }
  // Fields 5 and 6 are reserved; members follow in pairs.
  std::uint32_t total = 0;
  for (std::size_t i = 6; i < e.fields.size(); i += 2) {
    // "size, ;" ends a list with a pad member whose reference is empty.
    auto bits = integer(e, i, "member size in bits", 0, 0xFFFF);
    if (!bits) return std::nullopt;
    Member m;
    m.bits = static_cast<std::uint16_t>(*bits);
    const Field* ref = given(e, i + 1);
    if (ref == nullptr || (ref->quoted && ref->text.empty())) {
      m.kind = Member::Kind::kPadding;  // no reference, or "": an empty path
    } else if (ref->quoted) {
      auto p = path(e, i + 1, "member path");
      if (!p) return std::nullopt;
      m.kind = Member::Kind::kPath;
      m.path = *p;
    } else if (auto pn = number_after(ref->text, "Param")) {
      m.kind = Member::Kind::kParam;
      m.number = *pn;
    } else if (auto an = number_after(ref->text, "Assem")) {
      m.kind = Member::Kind::kAssembly;
      m.number = *an;
    } else {
      error(ref->line, fmt::format("{}: member {} \"{}\" is neither a path, ParamN nor AssemN",
                                   e.keyword, a.members.size() + 1, ref->text));
      return std::nullopt;
    }
    total += m.bits;
    a.members.push_back(m);
  }
  if (a.bits && !a.members.empty() && total != *a.bits) {
    error(e.line, fmt::format("{} ({}): its members take {} bits, its size is {}", e.keyword,
                              a.name, total, *a.bits));
    return std::nullopt;
  }
  return a;
}

}  // namespace dnbridge::profiles::eds::eds_file_detail
