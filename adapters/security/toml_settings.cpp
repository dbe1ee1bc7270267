#include "adapters/security/toml_settings.hpp"

#include <fmt/format.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>

namespace dnbridge::security {
namespace {

struct FileKey {
  std::string_view key;
  std::filesystem::path Settings::*field;
};

constexpr std::array<FileKey, 6> kRequired{{
    {"identity_ca", &Settings::identity_ca},
    {"certificate", &Settings::certificate},
    {"private_key", &Settings::private_key},
    {"permissions_ca", &Settings::permissions_ca},
    {"governance", &Settings::governance},
    {"permissions", &Settings::permissions},
}};
constexpr std::string_view kPlugins = "plugins";
constexpr std::array<std::string_view, 7> kKeys{"identity_ca",    "certificate", "private_key",
                                                "permissions_ca", "governance",  "permissions",
                                                kPlugins};

std::optional<std::filesystem::path> read_path(const toml::node& n, std::string_view key,
                                               std::vector<toml_config::Problem>& problems) {
  const auto* v = n.as_string();
  if (v == nullptr || v->get().empty()) {
    problems.push_back({n.source(), fmt::format("security.{} must be a file path (a non-empty "
                                                "string)",
                                                key)});
    return std::nullopt;
  }
  return std::filesystem::path(v->get());
}

}  // namespace

std::optional<Settings> read_table(const toml::node& node,
                                   std::vector<toml_config::Problem>& problems) {
  const toml::table* t = node.as_table();
  if (t == nullptr) {
    problems.push_back({node.source(), "security must be a table ([security])"});
    return std::nullopt;
  }
  const std::size_t before = problems.size();
  for (auto& p : toml_config::unknown_keys(*t, "[security]", kKeys))
    problems.push_back(std::move(p));
  Settings s;
  for (const FileKey& k : kRequired) {
    const toml::node* n = t->get(k.key);
    if (n == nullptr) {
      problems.push_back(
          {t->source(), fmt::format("missing required key '{}' in [security]", k.key)});
    } else if (auto p = read_path(*n, k.key, problems)) {
      s.*k.field = *p;
    }
  }
  if (const toml::node* n = t->get(kPlugins)) {
    if (auto p = read_path(*n, kPlugins, problems)) s.plugin_directory = *p;
  }
  if (problems.size() != before) return std::nullopt;
  return s;
}

Settings load_file(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) throw SettingsError(fmt::format("{}: cannot open: {}", name, std::strerror(errno)));
  std::ostringstream text;
  text << in.rdbuf();
  toml::table root;
  try {
    root = toml::parse(text.str(), name);
  } catch (const toml::parse_error& e) {
    throw SettingsError(toml_config::format(name, {e.source(), std::string(e.description())}));
  }
  const toml::node* n = root.get("security");
  if (n == nullptr) {
    throw SettingsError(
        fmt::format("{}: has no [security] table (identity_ca, certificate, "
                    "private_key, permissions_ca, governance, permissions)",
                    name));
  }
  std::vector<toml_config::Problem> problems;
  auto settings = read_table(*n, problems);
  if (!settings) {
    std::vector<std::string> lines;
    for (const auto& p : problems) lines.push_back(toml_config::format(name, p));
    throw SettingsError(toml_config::join_lines(lines));
  }
  settings->resolve_relative_to(std::filesystem::absolute(file).parent_path());
  return *settings;
}

}  // namespace dnbridge::security
