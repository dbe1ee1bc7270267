#include "bridge/profiles/eds/eds_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <set>

#include "bridge/common/text.hpp"
#include "bridge/profiles/eds/io_layout.hpp"

namespace dnbridge::eds {

std::string_view to_string(ConnectionKind kind) noexcept {
  switch (kind) {
    case ConnectionKind::kPoll:
      return "poll";
    case ConnectionKind::kStrobe:
      return "bit-strobe";
    case ConnectionKind::kChangeOfState:
      return "change of state";
    case ConnectionKind::kCyclic:
      return "cyclic";
  }
  return "?";
}

std::string to_string(ConnectionKinds kinds) {
  std::string out;
  for (ConnectionKind k : kConnectionKinds) {
    if (!kinds.has(k)) continue;
    if (!out.empty()) out += ", ";
    out += to_string(k);
  }
  return out.empty() ? "none" : out;
}

const DataType* data_type(std::uint8_t code) noexcept {
  static constexpr DataType kTypes[] = {
      {0xC1, "BOOL", 1, false, false},         {0xC2, "SINT", 1, true, false},
      {0xC3, "INT", 2, true, false},           {0xC4, "DINT", 4, true, false},
      {0xC5, "LINT", 8, true, false},          {0xC6, "USINT", 1, false, false},
      {0xC7, "UINT", 2, false, false},         {0xC8, "UDINT", 4, false, false},
      {0xC9, "ULINT", 8, false, false},        {0xCA, "REAL", 4, true, true},
      {0xCB, "LREAL", 8, true, true},          {0xD0, "STRING", 0, false, false},
      {0xD1, "BYTE", 1, false, false},         {0xD2, "WORD", 2, false, false},
      {0xD3, "DWORD", 4, false, false},        {0xD4, "LWORD", 8, false, false},
      {0xDA, "SHORT_STRING", 0, false, false},
  };
  for (const auto& t : kTypes) {
    if (t.code == code) return &t;
  }
  return nullptr;
}

const ConnectionInfo* IoInfo::connection(ConnectionKind kind) const noexcept {
  for (const auto& c : connections) {
    if (c.kind == kind) return &c;
  }
  return nullptr;
}

namespace {

const IoData* numbered(const std::vector<IoData>& list, unsigned number) noexcept {
  for (const auto& d : list) {
    if (d.number == number) return &d;
  }
  return nullptr;
}

}  // namespace

const IoData* IoInfo::input(unsigned number) const noexcept { return numbered(inputs, number); }
const IoData* IoInfo::output(unsigned number) const noexcept { return numbered(outputs, number); }

const Param* EdsFile::param(unsigned number) const noexcept {
  for (const auto& p : params) {
    if (p.number == number) return &p;
  }
  return nullptr;
}

namespace {

// "Input12" with prefix "Input": 12. Nothing when the keyword is not the
// prefix followed by a number from 1.
std::optional<unsigned> number_after(std::string_view keyword, std::string_view prefix) {
  if (keyword.size() <= prefix.size() || !iequals(keyword.substr(0, prefix.size()), prefix)) {
    return std::nullopt;
  }
  const std::string_view digits = keyword.substr(prefix.size());
  unsigned n = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), n);
  if (ec != std::errc{} || end != digits.data() + digits.size() || n == 0) return std::nullopt;
  return n;
}

}  // namespace

bool EdsFile::param_left_out(unsigned number) const noexcept {
  return std::find(params_left_out.begin(), params_left_out.end(), number) != params_left_out.end();
}

std::optional<unsigned> param_number(std::string_view name) noexcept {
  return number_after(name, "Param");
}

const Param* EdsFile::param(std::string_view name) const noexcept {
  if (auto n = param_number(name)) return param(*n);
  const Param* found = nullptr;
  for (const auto& p : params) {
    if (!iequals(p.name, name)) continue;
    if (found != nullptr) return nullptr;  // several
    found = &p;
  }
  return found;
}

std::vector<unsigned> EdsFile::params_named(std::string_view name) const {
  std::vector<unsigned> numbers;
  for (const auto& p : params) {
    if (iequals(p.name, name)) numbers.push_back(p.number);
  }
  return numbers;
}

const Assembly* EdsFile::assembly_at(const cip::EPath& path) const noexcept {
  if (path.class_id != 4u || !path.instance_id) return nullptr;
  for (const auto& a : assemblies) {
    if (a.path.class_id == 4u && a.path.instance_id == path.instance_id) return &a;
  }
  return nullptr;
}

std::string format_problem(std::string_view file, const Problem& problem) {
  return fmt::format("{}:{}: {}: {}", file, problem.line,
                     problem.severity == Problem::Severity::kError ? "error" : "warning",
                     problem.message);
}

namespace {

// An entry's identity: "param5" for Param5 or PARAM05 (the numbered
// keywords by their number), the keyword in lower case for the others.
std::string entry_key(std::string_view keyword) {
  for (std::string_view prefix : {"Input", "Output", "Param", "Assem"}) {
    if (auto n = number_after(keyword, prefix)) return fmt::format("{}{}", to_lower(prefix), *n);
  }
  return to_lower(keyword);
}

class Reader {
 public:
  explicit Reader(Parsed& out) : out_(out) {}

  std::optional<EdsFile> read(const Text& text) {
    EdsFile file;
    if (const Section* s = text.find("File")) {
      if (const Entry* e = s->find("DescText")) file.description = string(*e, 0);
      if (const Entry* e = s->find("Revision")) file.revision = string(*e, 0);
    }
    std::set<std::string> seen;
    for (const Section& section : text.sections) {
      if (!seen.insert(to_lower(section.name)).second) {
        warning(section.line,
                fmt::format("[{}] is given again: only the first is read", section.name));
      }
    }
    const Section* device_section = text.find("Device");
    if (device_section == nullptr) {
      error(1, "no [Device] section: the identity a node is checked by is missing");
    } else {
      device(*device_section, file.device);
    }
    if (const Section* s = text.find("IO_Info")) io_info(*s, file.io);
    if (const Section* s = text.find("Params"))
      numbered_entries(*s, "Param", file.params, &Reader::param);
    if (const Section* s = text.find("Assembly")) {
      numbered_entries(*s, "Assem", file.assemblies, &Reader::assembly);
    }
    cross_check(file);
    if (out_.errors > 0) return std::nullopt;
    // In a file read without an error, an entry found wrong was left out
    // with a warning.
    for (const std::string& key : failed_) {
      if (auto n = number_after(key, "Param")) file.params_left_out.push_back(*n);
    }
    return file;
  }

 private:
  void error(std::uint32_t line, std::string message) {
    add(line, Problem::Severity::kError, std::move(message));
  }
  void warning(std::uint32_t line, std::string message) {
    add(line, Problem::Severity::kWarning, std::move(message));
  }
  void add(std::uint32_t line, Problem::Severity severity, std::string message) {
    if (severity == Problem::Severity::kError) ++out_.errors;
    if (out_.problems.size() < kMaxProblemsKept) {
      out_.problems.push_back({line, severity, std::move(message)});
    } else {
      ++out_.not_shown;
    }
  }
  // An entry found wrong (said already): what refers to it says nothing more.
  void failed(const Entry& e) { failed_.insert(entry_key(e.keyword)); }
  bool has_failed(std::string_view keyword) const { return failed_.count(entry_key(keyword)) != 0; }

  // Field `i` of `e`, or an error naming `what` and nullptr.
  const Field* field(const Entry& e, std::size_t i, std::string_view what) {
    if (i < e.fields.size()) return &e.fields[i];
    error(e.line, fmt::format("{}: field {} ({}) is missing", e.keyword, i + 1, what));
    return nullptr;
  }
  // Field `i` when present and not empty.
  static const Field* given(const Entry& e, std::size_t i) {
    return i < e.fields.size() && !e.fields[i].empty() ? &e.fields[i] : nullptr;
  }

  std::string string(const Entry& e, std::size_t i) {
    return i < e.fields.size() ? e.fields[i].text : std::string{};
  }

  // An integer in [lo, hi]: decimal, or hexadecimal after 0x, with a sign.
  std::optional<std::int64_t> integer(const Entry& e, std::size_t i, std::string_view what,
                                      std::int64_t lo, std::int64_t hi) {
    const Field* f = field(e, i, what);
    if (f == nullptr) return std::nullopt;
    std::string_view t = f->text;
    bool negative = false;
    if (!t.empty() && (t.front() == '-' || t.front() == '+')) {
      negative = t.front() == '-';
      t.remove_prefix(1);
    }
    int base = 10;
    if (has_hex_prefix(t)) {
      base = 16;
      t.remove_prefix(2);
    }
    std::uint64_t magnitude = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), magnitude, base);
    if (f->quoted || t.empty() || end != t.data() + t.size() ||
        (ec != std::errc{} && ec != std::errc::result_out_of_range)) {
      error(f->line, fmt::format("{}: {} \"{}\" is not a number", e.keyword, what, f->text));
      return std::nullopt;
    }
    if (ec == std::errc::result_out_of_range ||
        magnitude > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
      error(f->line,
            fmt::format("{}: {} {} is out of range ({}..{})", e.keyword, what, f->text, lo, hi));
      return std::nullopt;
    }
    const auto value =
        negative ? -static_cast<std::int64_t>(magnitude) : static_cast<std::int64_t>(magnitude);
    if (value < lo || value > hi) {
      error(f->line,
            fmt::format("{}: {} {} is out of range ({}..{})", e.keyword, what, f->text, lo, hi));
      return std::nullopt;
    }
    return value;
  }

  // A number that may have a fraction (parameter limits and scaling); an
  // empty field gives nothing, without a problem.
  std::optional<double> real(const Entry& e, std::size_t i, std::string_view what) {
    const Field* f = given(e, i);
    if (f == nullptr) return std::nullopt;
    std::string_view t = f->text;
    const std::string_view digits =
        !t.empty() && (t.front() == '-' || t.front() == '+') ? t.substr(1) : t;
    if (has_hex_prefix(digits)) {
      if (auto v = integer(e, i, what, -std::numeric_limits<std::int64_t>::max(),
                           std::numeric_limits<std::int64_t>::max())) {
        return static_cast<double>(*v);
      }
      return std::nullopt;
    }
    if (!t.empty() && t.front() == '+') t.remove_prefix(1);
    double v = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (f->quoted || t.empty() || ec != std::errc{} || end != t.data() + t.size() ||
        !std::isfinite(v)) {
      error(f->line, fmt::format("{}: {} \"{}\" is not a number", e.keyword, what, f->text));
      return std::nullopt;
    }
    return v;
  }

  // A path given as hex bytes ("20 04 24 64 30 03"); `size`, when given, is
  // the byte count the entry states for it.
  std::optional<cip::EPath> path(const Entry& e, std::size_t i, std::string_view what,
                                 std::optional<std::int64_t> size = std::nullopt) {
    const Field* f = field(e, i, what);
    if (f == nullptr) return std::nullopt;
    const HexBytes hex = parse_hex_bytes(f->text, " \t");
    if (hex.error == HexBytes::Error::kNotHexDigit) {
      error(f->line, fmt::format("{}: {} \"{}\" is not hex bytes", e.keyword, what, f->text));
      return std::nullopt;
    }
    if (hex.error == HexBytes::Error::kOneDigit) {
      error(f->line,
            fmt::format("{}: {} \"{}\": a byte of one hex digit", e.keyword, what, f->text));
      return std::nullopt;
    }
    const std::vector<std::uint8_t>& bytes = hex.bytes;
    if (size && *size != static_cast<std::int64_t>(bytes.size())) {
      error(f->line, fmt::format("{}: {} has {} bytes, its size field says {}", e.keyword, what,
                                 bytes.size(), *size));
      return std::nullopt;
    }
    auto decoded = cip::decode_epath(Bytes(bytes.data(), bytes.size()));
    if (!decoded) {
      error(f->line, fmt::format("{}: {} \"{}\" is not a path of class, instance and attribute "
                                 "segments ({})",
                                 e.keyword, what, f->text, decoded.error().message()));
      return std::nullopt;
    }
    return *decoded;
  }

  void device(const Section& s, Device& d) {
    const auto required = [&](std::string_view keyword, std::int64_t hi, auto& out) -> void {
      const Entry* e = s.find(keyword);
      if (e == nullptr) {
        error(s.line, fmt::format("[Device] has no {}", keyword));
        return;
      }
      if (auto v = integer(*e, 0, "value", 0, hi)) {
        out = static_cast<std::remove_reference_t<decltype(out)>>(*v);
      }
    };
    std::set<std::string> seen;
    for (const Entry& e : s.entries) {
      if (!seen.insert(to_lower(e.keyword)).second) {
        warning(e.line,
                fmt::format("[Device] {} is given again: only the first is read", e.keyword));
      }
    }
    required("VendCode", 0xFFFF, d.vendor_code);
    required("ProdType", 0xFFFF, d.product_type);
    required("ProdCode", 0xFFFF, d.product_code);
    required("MajRev", 0xFF, d.major_revision);
    required("MinRev", 0xFF, d.minor_revision);
    if (const Entry* e = s.find("VendName")) d.vendor_name = string(*e, 0);
    if (const Entry* e = s.find("ProdTypeStr")) d.product_type_name = string(*e, 0);
    if (const Entry* e = s.find("ProdName")) d.product_name = string(*e, 0);
    if (const Entry* e = s.find("Catalog")) d.catalog = string(*e, 0);
  }

  std::optional<ConnectionKinds> kinds(const Entry& e, std::size_t i, std::string_view what) {
    auto v = integer(e, i, what, 0, 0xFFFF);
    if (!v) return std::nullopt;
    const auto bits = static_cast<std::uint16_t>(*v);
    if ((bits & ~0x000Fu) != 0) {
      warning(e.line, fmt::format("{}: {} 0x{:04X} has bits beyond poll, bit-strobe, change of "
                                  "state and cyclic; those are ignored",
                                  e.keyword, what, bits));
    }
    return ConnectionKinds{static_cast<std::uint16_t>(bits & 0x000F)};
  }

  void io_info(const Section& s, IoInfo& io) {
    static constexpr std::pair<std::string_view, ConnectionKind> kInfos[] = {
        {"PollInfo", ConnectionKind::kPoll},
        {"StrobeInfo", ConnectionKind::kStrobe},
        {"COSInfo", ConnectionKind::kChangeOfState},
        {"CyclicInfo", ConnectionKind::kCyclic}};
    for (const Entry& e : s.entries) {
      if (iequals(e.keyword, "Default")) {
        if (defaults_line_ != 0) {
          error(e.line, "Default is given twice");
          continue;
        }
        defaults_line_ = e.line;
        if (auto k = kinds(e, 0, "default connections")) io.defaults = *k;
        continue;
      }
      bool known = false;
      for (const auto& [keyword, kind] : kInfos) {
        if (!iequals(e.keyword, keyword)) continue;
        known = true;
        if (io.connection(kind) != nullptr) {
          error(e.line, fmt::format("{} is given twice", e.keyword));
          break;
        }
        auto combines = kinds(e, 0, "the connections it combines with");
        auto input = integer(e, 1, "its input", 0, 0xFFFF);
        auto output = integer(e, 2, "its output", 0, 0xFFFF);
        if (combines && input && output) {
          io.connections.push_back({kind, *combines, static_cast<unsigned>(*input),
                                    static_cast<unsigned>(*output), e.line});
        } else {
          failed(e);
        }
      }
      if (known) continue;
      if (auto n = number_after(e.keyword, "Input")) {
        io_data(e, *n, io.inputs);
      } else if (auto m = number_after(e.keyword, "Output")) {
        io_data(e, *m, io.outputs);
      }
      // Other keywords (vendors' own) are not dnbridge's.
    }
  }

  void io_data(const Entry& e, unsigned number, std::vector<IoData>& list) {
    if (numbered(list, number) != nullptr) {
      error(e.line, fmt::format("{} is given twice", e.keyword));
      return;
    }
    IoData d;
    d.number = number;
    d.line = e.line;
    auto size = integer(e, 0, "size in bytes", 0, 0xFFFF);
    auto bits = integer(e, 1, "bits used", 0, std::int64_t{0xFFFF} * 8);
    auto carried = kinds(e, 2, "the connections that carry it");
    d.name = string(e, 3);
    auto path_size = integer(e, 4, "path size", 0, 0xFF);
    std::optional<cip::EPath> p;
    if (path_size) p = path(e, 5, "path", *path_size);
    d.help = string(e, 6);
    if (!size || !bits || !carried || !p) {
      failed(e);
      return;
    }
    if (*bits > *size * 8) {
      error(e.line,
            fmt::format("{}: {} bits used do not fit in {} bytes", e.keyword, *bits, *size));
      failed(e);
      return;
    }
    d.size = static_cast<std::uint16_t>(*size);
    d.bits_used = static_cast<std::uint16_t>(*bits);
    d.carried_by = *carried;
    d.path = *p;
    list.push_back(std::move(d));
  }

  // The numbered entries PREFIXn of a section, each read by `read_one` (which
  // reports its own errors); one given twice is an error, whether or not the
  // first was read.
  template <typename T, typename Read>
  void numbered_entries(const Section& s, std::string_view prefix, std::vector<T>& out,
                        Read read_one) {
    std::set<unsigned> seen;
    for (const Entry& e : s.entries) {
      auto n = number_after(e.keyword, prefix);
      if (!n) continue;  // other entries (Enum, Group, vendors') are not read
      if (!seen.insert(*n).second) {
        error(e.line, fmt::format("{} is given twice", e.keyword));
        continue;
      }
      if (auto item = (this->*read_one)(e, *n)) {
        out.push_back(std::move(*item));
      } else {
        failed(e);
      }
    }
  }

  std::optional<Param> param(const Entry& e, unsigned number) {
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
      error(e.line, fmt::format("{} ({}): default {} is outside {}..{}", e.keyword, p.name,
                                *p.default_value, p.minimum.value_or(-INFINITY),
                                p.maximum.value_or(INFINITY)));
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

  std::optional<Assembly> assembly(const Entry& e, unsigned number) {
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

  // AssemN members that lead back to an assembly they are in.
  void assembly_cycles(const EdsFile& f) {
    const auto find = [&](unsigned n) -> const Assembly* {
      for (const Assembly& a : f.assemblies) {
        if (a.number == n) return &a;
      }
      return nullptr;
    };
    for (const Assembly& start : f.assemblies) {
      // Depth-first along AssemN members, as far as there are assemblies.
      std::vector<std::pair<const Assembly*, std::size_t>> stack{{&start, 0}};
      std::set<unsigned> on_path{start.number};
      bool found = false;
      while (!stack.empty() && !found) {
        auto& [a, next] = stack.back();
        if (next == a->members.size()) {
          on_path.erase(a->number);
          stack.pop_back();
          continue;
        }
        const Member& m = a->members[next++];
        if (m.kind != Member::Kind::kAssembly) continue;
        if (m.number == start.number) {
          error(start.line, fmt::format("Assem{} ({}) contains itself through its members",
                                        start.number, start.name));
          failed_.insert(entry_key(fmt::format("Assem{}", start.number)));
          found = true;
          continue;
        }
        const Assembly* nested = find(m.number);
        if (nested != nullptr && on_path.insert(nested->number).second) {
          stack.emplace_back(nested, 0);
        }
      }
    }
  }

  void cross_check(const EdsFile& f) {
    assembly_cycles(f);
    for (const auto& c : f.io.connections) {
      if (c.input != 0 && f.io.input(c.input) == nullptr &&
          !has_failed(fmt::format("Input{}", c.input))) {
        error(c.line, fmt::format("{} connection: Input{} is not in [IO_Info]", to_string(c.kind),
                                  c.input));
      }
      if (c.output != 0 && f.io.output(c.output) == nullptr &&
          !has_failed(fmt::format("Output{}", c.output))) {
        error(c.line, fmt::format("{} connection: Output{} is not in [IO_Info]", to_string(c.kind),
                                  c.output));
      }
    }
    for (ConnectionKind k : kConnectionKinds) {
      const std::string_view info = k == ConnectionKind::kPoll     ? "PollInfo"
                                    : k == ConnectionKind::kStrobe ? "StrobeInfo"
                                    : k == ConnectionKind::kCyclic ? "CyclicInfo"
                                                                   : "COSInfo";
      if (f.io.defaults.has(k) && f.io.connection(k) == nullptr && !has_failed(info)) {
        error(defaults_line_, fmt::format("[IO_Info] Default names {}, which no {} entry describes",
                                          to_string(k), info));
      }
    }
    for (const auto* list : {&f.io.inputs, &f.io.outputs}) {
      for (const IoData& d : *list) {
        const Assembly* a = f.assembly_at(d.path);
        if (a != nullptr && (a->bits || !a->members.empty()) && a->size_bits() != d.size * 8u) {
          error(d.line, fmt::format("{} ({}) is {} bytes, the Assem{} it names is {} bits",
                                    list == &f.io.inputs ? "an input" : "an output", d.name, d.size,
                                    a->number, a->size_bits()));
        }
      }
    }
    for (const Assembly& a : f.assemblies) {
      for (const Member& m : a.members) {
        if (m.kind == Member::Kind::kParam) {
          const Param* p = f.param(m.number);
          if (p == nullptr && has_failed(fmt::format("Param{}", m.number))) {
            // Said where the parameter is.
          } else if (p == nullptr) {
            error(a.line, fmt::format("Assem{} ({}): member Param{} is not in [Params]", a.number,
                                      a.name, m.number));
          } else if (p->type.size != 0 && m.bits > p->size * 8u) {
            error(a.line, fmt::format("Assem{} ({}): member Param{} ({}) is {} bits, the "
                                      "parameter {} ({} bits)",
                                      a.number, a.name, m.number, p->name, m.bits, p->type.name,
                                      p->size * 8u));
          }
        } else if (m.kind == Member::Kind::kAssembly &&
                   !has_failed(fmt::format("Assem{}", m.number)) &&
                   std::none_of(f.assemblies.begin(), f.assemblies.end(),
                                [&](const Assembly& b) { return b.number == m.number; })) {
          error(a.line, fmt::format("Assem{} ({}): member Assem{} is not in [Assembly]", a.number,
                                    a.name, m.number));
        }
      }
    }
  }

  Parsed& out_;
  std::set<std::string> failed_;
  std::uint32_t defaults_line_ = 0;
};

}  // namespace

Parsed parse(std::string_view text) {
  Lexed lexed = lex(text);
  Parsed out;
  out.problems = std::move(lexed.problems);
  out.errors = lexed.errors;
  out.not_shown = lexed.not_kept;
  Reader reader(out);
  auto file = reader.read(lexed.text);
  // Errors first, then warnings, kMaxProblems of them, in line order.
  std::stable_sort(
      out.problems.begin(), out.problems.end(), [](const Problem& a, const Problem& b) {
        return a.severity == Problem::Severity::kError && b.severity != Problem::Severity::kError;
      });
  if (out.problems.size() > kMaxProblems) {
    out.not_shown += out.problems.size() - kMaxProblems;
    out.problems.resize(kMaxProblems);
  }
  std::stable_sort(out.problems.begin(), out.problems.end(),
                   [](const Problem& a, const Problem& b) { return a.line < b.line; });
  out.file = std::move(file);
  return out;
}

}  // namespace dnbridge::eds
