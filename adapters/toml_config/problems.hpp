#pragma once
// Problems found in a TOML configuration, with where they are, for readers
// that report all of them at once ("FILE:LINE:COLUMN: what is wrong").
#include <toml++/toml.h>

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace dnbridge::toml_config {

struct Problem {
  toml::source_region at;
  std::string text;
};

struct UnknownKey {
  std::string_view key;
  toml::source_region at;
  std::string text;
};

// A misspelt key must not fall back silently to a default: one problem per
// key of `table` not in `known`, "unknown key 'x' in WHERE", with the
// closest key of `hints` as a hint when one is close.
std::vector<UnknownKey> unknown_keys(const toml::table& table, std::string_view where,
                                     std::span<const std::string_view> known,
                                     std::span<const std::string_view> hints);

// What a value is, for "KEY must be ..., not a string": "a string",
// "an integer", "a table", ...
std::string_view type_name(toml::node_type type);

// "FILE:LINE:COLUMN: text" (lines and columns from 1).
std::string format(std::string_view source, const Problem& problem);

// Problems as one message: one a line.
std::string join_lines(const std::vector<std::string>& lines);

}  // namespace dnbridge::toml_config
