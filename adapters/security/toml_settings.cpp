#include "adapters/security/toml_settings.hpp"

#include <fmt/format.h>

#include <array>
#include <string_view>
#include <utility>

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

std::optional<std::filesystem::path> read_path(const toml::node& n, std::string_view key,
                                               toml_config::Problems& problems) {
  const auto* v = n.as_string();
  if (v == nullptr || v->get().empty()) {
    problems.error(n.source(), fmt::format("security.{} must be a file path (a non-empty "
                                           "string)",
                                           key));
    return std::nullopt;
  }
  return std::filesystem::path(v->get());
}

}  // namespace

std::optional<Settings> read_table(const toml::node& node, toml_config::Problems& problems,
                                   std::vector<std::string_view> allowed) {
  const toml::table* t = node.as_table();
  if (t == nullptr) {
    problems.error(node.source(), "security must be a table ([security])");
    return std::nullopt;
  }
  toml_config::TableReader table(*t, "[security]", problems);
  if (!allowed.empty()) table.allow_only(std::move(allowed));
  const std::size_t before = problems.error_count();
  Settings s;
  for (const FileKey& k : kRequired) {
    if (const toml::node* n = table.require(k.key)) {
      if (auto p = read_path(*n, k.key, problems)) s.*k.field = *p;
    }
  }
  if (const toml::node* n = table.get(kPlugins)) {
    if (auto p = read_path(*n, kPlugins, problems)) s.plugin_directory = *p;
  }
  table.finish();
  if (problems.error_count() != before) return std::nullopt;
  return s;
}

Settings load_file(const std::filesystem::path& file) {
  const std::string name = file.string();
  auto text = toml_config::read_file(file, "a security file");
  if (!text.text) throw SettingsError(text.error);
  toml_config::Problems problems(name);
  const auto root = toml_config::parse(*text.text, problems);
  if (!root) throw SettingsError(toml_config::join_lines(problems.errors()));
  const toml::node* n = root->get("security");
  if (n == nullptr) {
    throw SettingsError(
        fmt::format("{}: has no [security] table (identity_ca, certificate, "
                    "private_key, permissions_ca, governance, permissions)",
                    name));
  }
  auto settings = read_table(*n, problems);
  if (!settings) throw SettingsError(toml_config::join_lines(problems.errors()));
  settings->resolve_relative_to(std::filesystem::absolute(file).parent_path());
  return *settings;
}

}  // namespace dnbridge::security
