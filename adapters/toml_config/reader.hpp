#pragma once
// The kit every TOML configuration of dnbridge is read with (the rack's,
// [security], cdn127-sim's devices): problems collected with their place and
// reported all at once in the file's order, typed reads of values with the
// same words everywhere, and tables whose allowed keys are the keys the code
// reads: a TableReader declares every key it is asked for, and reports any
// other key the table holds as unknown, with the closest declared key as a
// hint. Where a file's keys are documented in a table of their own (the rack
// file's, adapters/daemon/config_keys.hpp), allow_only holds the reader to
// it.
#include <toml++/toml.h>

#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "adapters/toml_config/problems.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::toml_config {

// Errors and warnings of one file, each "FILE:LINE:COLUMN: text" (lines and
// columns from 1), sorted by position. The same problem at the same place is
// kept once (a [defaults] value read again for every node that inherits it).
class Problems {
 public:
  explicit Problems(std::string source) : source_(std::move(source)) {}

  void error(const toml::source_region& at, std::string text);
  void warning(const toml::source_region& at, std::string text);
  bool has_errors() const noexcept { return !errors_.empty(); }
  std::size_t error_count() const noexcept { return errors_.size(); }
  std::vector<std::string> errors() const { return format(errors_); }
  std::vector<std::string> warnings() const { return format(warnings_); }
  const std::string& source() const noexcept { return source_; }

 private:
  struct Entry {
    std::uint32_t line = 1;
    std::uint32_t column = 1;
    std::string text;
  };
  void add(std::vector<Entry>& list, const toml::source_region& at, std::string text);
  std::vector<std::string> format(std::vector<Entry> list) const;

  std::string source_;
  std::vector<Entry> errors_;
  std::vector<Entry> warnings_;
  std::set<std::tuple<std::uint32_t, std::uint32_t, std::string>> seen_;
};

// A configuration file's whole text, or why there is none: "PATH: is a
// directory, not WHAT", "PATH: cannot open: REASON", "PATH: cannot read: REASON".
struct FileText {
  std::optional<std::string> text;
  std::string error;
};
FileText read_file(const std::filesystem::path& path, std::string_view what);

// `text` parsed, or its syntax error added to `problems`.
std::optional<toml::table> parse(std::string_view text, Problems& problems);

// An integer's bounds, for "KEY = V is out of range (MIN..MAX UNIT)" or, with
// a note, "KEY = V is out of range: NOTE".
struct IntRange {
  std::int64_t min;
  std::int64_t max;
  std::string_view unit = {};  // " ms"
  std::string_view note = {};
};

// Typed reads of one value, named `key` in what they report; nullopt (and a
// problem at the value's place) when it is not what is asked for.
std::optional<std::string> read_string(const toml::node& n, std::string_view key, Problems& p);
// A non-empty string: a name operators read, a DDS key.
std::optional<std::string> read_name(const toml::node& n, std::string_view key, Problems& p);
std::optional<bool> read_bool(const toml::node& n, std::string_view key, Problems& p);
std::optional<double> read_number(const toml::node& n, std::string_view key, Problems& p);
std::optional<std::int64_t> read_integer(const toml::node& n, std::string_view key, IntRange range,
                                         Problems& p);
template <class T>
std::optional<T> read_int_as(const toml::node& n, std::string_view key, IntRange range,
                             Problems& p) {
  auto v = read_integer(n, key, range, p);
  if (!v) return std::nullopt;
  return static_cast<T>(*v);
}
std::optional<Duration> read_ms(const toml::node& n, std::string_view key, std::int64_t min,
                                std::int64_t max, Problems& p);

// Reads one table. Each key asked for (get, require) is declared; when the
// reader is done (finish(), or its end), every key the table holds that was
// never declared is reported as unknown.
class TableReader {
 public:
  // `where`: how problems name the table ("[[port]]", "[defaults]").
  TableReader(const toml::table& table, std::string where, Problems& problems)
      : table_(table), where_(std::move(where)), problems_(problems) {}
  // Finishes, unless an exception is on its way through (the reading is
  // abandoned then).
  ~TableReader() {
    if (std::uncaught_exceptions() == unwinding_) finish();
  }
  TableReader(const TableReader&) = delete;
  TableReader& operator=(const TableReader&) = delete;

  // Only the keys `allowed` may be asked for: another is a std::logic_error
  // (the reader and the table of its keys disagree). A key the table holds
  // and nobody asked for is reported as `explain` says, where it says
  // something ("KEY stands in ..."), else as unknown, with the closest
  // allowed key as a hint.
  using Explain = std::function<std::string(std::string_view key)>;
  void allow_only(std::vector<std::string_view> allowed, Explain explain = {});

  const toml::node* get(std::string_view key);
  // Missing: "missing required key 'KEY' in WHERE", at the table.
  const toml::node* require(std::string_view key);
  void finish();

  const toml::table& table() const noexcept { return table_; }
  const std::string& where() const noexcept { return where_; }
  Problems& problems() noexcept { return problems_; }

 private:
  const toml::table& table_;
  std::string where_;
  Problems& problems_;
  std::vector<std::string> declared_;
  std::optional<std::vector<std::string_view>> allowed_;
  Explain explain_;
  bool finished_ = false;
  int unwinding_ = std::uncaught_exceptions();
};

// `node` as a table, or "KEY must be a table (SPELLING), not ..." and null.
const toml::table* as_table(const toml::node& node, std::string_view key, std::string_view spelling,
                            Problems& p);

}  // namespace dnbridge::toml_config
