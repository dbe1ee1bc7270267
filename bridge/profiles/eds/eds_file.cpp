// The model's lookups and names, and parse(): the text lexed, then read into
// an EdsFile by Reader (eds_file_internal.hpp), its problems sorted.
#include "bridge/profiles/eds/eds_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <set>

#include "bridge/common/text.hpp"
#include "bridge/profiles/eds/eds_file_internal.hpp"

namespace dnbridge::profiles::eds {

using eds_file_detail::number_after;
using eds_file_detail::numbered;
using eds_file_detail::Reader;

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

namespace eds_file_detail {

const IoData* numbered(const std::vector<IoData>& list, unsigned number) noexcept {
  for (const auto& d : list) {
    if (d.number == number) return &d;
  }
  return nullptr;
}

}  // namespace eds_file_detail

const IoData* IoInfo::input(unsigned number) const noexcept { return numbered(inputs, number); }
const IoData* IoInfo::output(unsigned number) const noexcept { return numbered(outputs, number); }

const Param* EdsFile::param(unsigned number) const noexcept {
  for (const auto& p : params) {
    if (p.number == number) return &p;
  }
  return nullptr;
}

namespace eds_file_detail {

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

}  // namespace eds_file_detail

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

namespace eds_file_detail {

std::string entry_key(std::string_view keyword) {
  for (std::string_view prefix : {"Input", "Output", "Param", "Assem"}) {
    if (auto n = number_after(keyword, prefix)) return fmt::format("{}{}", to_lower(prefix), *n);
  }
  return to_lower(keyword);
}

std::optional<EdsFile> Reader::read(const Text& text) {
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

}  // namespace eds_file_detail

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

}  // namespace dnbridge::profiles::eds
