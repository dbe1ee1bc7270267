#include "adapters/toml_config/reader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace dnbridge::toml_config {

void Problems::error(const toml::source_region& at, std::string text) {
  add(errors_, at, std::move(text));
}

void Problems::warning(const toml::source_region& at, std::string text) {
  add(warnings_, at, std::move(text));
}

void Problems::add(std::vector<Entry>& list, const toml::source_region& at, std::string text) {
  // An empty document has no position; its problems are at its start.
  const std::uint32_t line = std::max<std::uint32_t>(at.begin.line, 1);
  const std::uint32_t column = std::max<std::uint32_t>(at.begin.column, 1);
  if (seen_.emplace(line, column, text).second) list.push_back({line, column, std::move(text)});
}

std::vector<std::string> Problems::format(std::vector<Entry> list) const {
  std::stable_sort(list.begin(), list.end(), [](const Entry& a, const Entry& b) {
    return std::tie(a.line, a.column) < std::tie(b.line, b.column);
  });
  std::vector<std::string> out;
  out.reserve(list.size());
  for (const auto& e : list) {
    out.push_back(fmt::format("{}:{}:{}: {}", source_, e.line, e.column, e.text));
  }
  return out;
}

FileText read_file(const std::filesystem::path& path, std::string_view what) {
  const std::string name = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return {std::nullopt, fmt::format("{}: is a directory, not {}", name, what)};
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return {std::nullopt, fmt::format("{}: cannot open: {}", name, std::strerror(errno))};
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad())
    return {std::nullopt, fmt::format("{}: cannot read: {}", name, std::strerror(errno))};
  return {text.str(), {}};
}

std::optional<toml::table> parse(std::string_view text, Problems& problems) {
  try {
    return toml::parse(text, problems.source());
  } catch (const toml::parse_error& e) {
    problems.error(e.source(), std::string(e.description()));
    return std::nullopt;
  }
}

std::optional<std::string> read_string(const toml::node& n, std::string_view key, Problems& p) {
  const auto* v = n.as_string();
  if (!v) {
    p.error(n.source(), fmt::format("{} must be a string, not {}", key, type_name(n.type())));
    return std::nullopt;
  }
  return v->get();
}

std::optional<std::string> read_name(const toml::node& n, std::string_view key, Problems& p) {
  auto v = read_string(n, key, p);
  if (v && v->empty()) {
    p.error(n.source(), fmt::format("{} must not be empty", key));
    return std::nullopt;
  }
  return v;
}

std::optional<bool> read_bool(const toml::node& n, std::string_view key, Problems& p) {
  const auto* v = n.as_boolean();
  if (!v) {
    p.error(n.source(), fmt::format("{} must be true or false, not {}", key, type_name(n.type())));
    return std::nullopt;
  }
  return v->get();
}

std::optional<double> read_number(const toml::node& n, std::string_view key, Problems& p) {
  if (const auto* i = n.as_integer()) return static_cast<double>(i->get());
  if (const auto* f = n.as_floating_point()) return f->get();
  p.error(n.source(), fmt::format("{} must be a number, not {}", key, type_name(n.type())));
  return std::nullopt;
}

std::optional<std::int64_t> read_integer(const toml::node& n, std::string_view key, IntRange range,
                                         Problems& p) {
  const auto* v = n.as_integer();
  if (!v) {
    p.error(n.source(), fmt::format("{} must be an integer, not {}", key, type_name(n.type())));
    return std::nullopt;
  }
  const std::int64_t value = v->get();
  if (value < range.min || value > range.max) {
    if (range.note.empty()) {
      p.error(n.source(), fmt::format("{} = {} is out of range ({}..{}{})", key, value, range.min,
                                      range.max, range.unit));
    } else {
      p.error(n.source(), fmt::format("{} = {} is out of range: {}", key, value, range.note));
    }
    return std::nullopt;
  }
  return value;
}

std::optional<Duration> read_ms(const toml::node& n, std::string_view key, std::int64_t min,
                                std::int64_t max, Problems& p) {
  auto v = read_integer(n, key, {min, max, " ms"}, p);
  if (!v) return std::nullopt;
  return milliseconds(*v);
}

void TableReader::allow_only(std::vector<std::string_view> allowed, Explain explain) {
  allowed_ = std::move(allowed);
  explain_ = std::move(explain);
}

const toml::node* TableReader::get(std::string_view key) {
  if (allowed_ && std::find(allowed_->begin(), allowed_->end(), key) == allowed_->end()) {
    throw std::logic_error(fmt::format(
        "{}: the reader asks for '{}', which the table of its keys does not list", where_, key));
  }
  if (std::find(declared_.begin(), declared_.end(), key) == declared_.end()) {
    declared_.emplace_back(key);
  }
  return table_.get(key);
}

const toml::node* TableReader::require(std::string_view key) {
  const toml::node* n = get(key);
  if (!n) {
    problems_.error(table_.source(), fmt::format("missing required key '{}' in {}", key, where_));
  }
  return n;
}

void TableReader::finish() {
  if (finished_) return;
  finished_ = true;
  const std::vector<std::string_view> declared(declared_.begin(), declared_.end());
  for (auto& p : unknown_keys(table_, where_, declared, allowed_ ? *allowed_ : declared)) {
    if (explain_) {
      const std::string why = explain_(p.key);
      if (!why.empty()) p.text = why;
    }
    problems_.error(p.at, std::move(p.text));
  }
}

const toml::table* as_table(const toml::node& node, std::string_view key, std::string_view spelling,
                            Problems& p) {
  const toml::table* t = node.as_table();
  if (!t) {
    p.error(node.source(),
            fmt::format("{} must be a table ({}), not {}", key, spelling, type_name(node.type())));
  }
  return t;
}

}  // namespace dnbridge::toml_config
