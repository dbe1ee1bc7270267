#include "adapters/toml_config/problems.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "bridge/common/closest.hpp"

namespace dnbridge::toml_config {
std::vector<UnknownKey> unknown_keys(const toml::table& table, std::string_view where,
                                     std::span<const std::string_view> known,
                                     std::span<const std::string_view> hints) {
  std::vector<UnknownKey> out;
  for (auto&& [key, value] : table) {
    const std::string_view name = key.str();
    if (std::find(known.begin(), known.end(), name) != known.end()) continue;
    std::string hint;
    if (const auto k = closest(name, hints)) hint = fmt::format(" (did you mean '{}'?)", *k);
    out.push_back({name, key.source(), fmt::format("unknown key '{}' in {}{}", name, where, hint)});
  }
  return out;
}

std::string_view type_name(toml::node_type type) {
  switch (type) {
    case toml::node_type::none:
      return "nothing";
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a floating-point number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
  }
  return "an unknown type";
}

std::string format(std::string_view source, const Problem& problem) {
  // An empty document has no position; its problems are at its start.
  return fmt::format("{}:{}:{}: {}", source, std::max<std::uint32_t>(problem.at.begin.line, 1),
                     std::max<std::uint32_t>(problem.at.begin.column, 1), problem.text);
}

std::string join_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) {
    if (!out.empty()) out += '\n';
    out += l;
  }
  return out;
}

}  // namespace dnbridge::toml_config
