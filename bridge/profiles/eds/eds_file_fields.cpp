// Reader: the problems it reports, and an entry's fields read as strings,
// integers, reals and paths.
#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <limits>

#include "bridge/common/text.hpp"
#include "bridge/profiles/eds/eds_file_internal.hpp"

namespace dnbridge::profiles::eds::eds_file_detail {

void Reader::error(std::uint32_t line, std::string message) {
  add(line, Problem::Severity::kError, std::move(message));
}
void Reader::warning(std::uint32_t line, std::string message) {
  add(line, Problem::Severity::kWarning, std::move(message));
}
void Reader::add(std::uint32_t line, Problem::Severity severity, std::string message) {
  if (severity == Problem::Severity::kError) ++out_.errors;
  if (out_.problems.size() < kMaxProblemsKept) {
    out_.problems.push_back({line, severity, std::move(message)});
  } else {
    ++out_.not_shown;
  }
}
// An entry found wrong (said already): what refers to it says nothing more.
void Reader::failed(const Entry& e) { failed_.insert(entry_key(e.keyword)); }
bool Reader::has_failed(std::string_view keyword) const {
  return failed_.count(entry_key(keyword)) != 0;
}

// Field `i` of `e`, or an error naming `what` and nullptr.
const Field* Reader::field(const Entry& e, std::size_t i, std::string_view what) {
  if (i < e.fields.size()) return &e.fields[i];
  error(e.line, fmt::format("{}: field {} ({}) is missing", e.keyword, i + 1, what));
  return nullptr;
}
// Field `i` when present and not empty.
const Field* Reader::given(const Entry& e, std::size_t i) {
  return i < e.fields.size() && !e.fields[i].empty() ? &e.fields[i] : nullptr;
}

std::string Reader::string(const Entry& e, std::size_t i) {
  return i < e.fields.size() ? e.fields[i].text : std::string{};
}

// An integer in [lo, hi]: decimal, or hexadecimal after 0x, with a sign.
std::optional<std::int64_t> Reader::integer(const Entry& e, std::size_t i, std::string_view what,
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
std::optional<double> Reader::real(const Entry& e, std::size_t i, std::string_view what) {
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
std::optional<cip::EPath> Reader::path(const Entry& e, std::size_t i, std::string_view what,
                                       std::optional<std::int64_t> size) {
  const Field* f = field(e, i, what);
  if (f == nullptr) return std::nullopt;
  const HexBytes hex = parse_hex_bytes(f->text, " \t");
  if (hex.error == HexBytes::Error::kNotHexDigit) {
    error(f->line, fmt::format("{}: {} \"{}\" is not hex bytes", e.keyword, what, f->text));
    return std::nullopt;
  }
  if (hex.error == HexBytes::Error::kOneDigit) {
    error(f->line, fmt::format("{}: {} \"{}\": a byte of one hex digit", e.keyword, what, f->text));
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

}  // namespace dnbridge::profiles::eds::eds_file_detail
