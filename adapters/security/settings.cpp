#include "adapters/security/settings.hpp"

#include <string>

namespace dnbridge::security {

std::filesystem::path Settings::default_plugin_directory() {
  return DNBRIDGE_DDS_SECURITY_PLUGIN_DIR;  // from CMake (adapters/security/CMakeLists.txt)
}

void Settings::resolve_relative_to(const std::filesystem::path& directory) {
  for (auto* p : {&identity_ca, &certificate, &private_key, &permissions_ca, &governance,
                  &permissions, &plugin_directory}) {
    if (!p->empty() && p->is_relative()) *p = directory / *p;
  }
}

std::filesystem::path plugin_library(const Settings& settings, std::string_view plugin) {
  const std::string name = "dds_security_" + std::string(plugin);
  // By name, Cyclone tries libNAME.so on the loader's search path.
  if (settings.plugin_directory.empty()) return name;
  return settings.plugin_directory / ("lib" + name + ".so");
}

dds::Properties participant_properties(const Settings& s) {
  // DDS Security 1.1, 9.3.1 and 9.4.1: the built-in plugins' properties.
  const auto file = [](const std::filesystem::path& p) { return "file:" + p.string(); };
  return {
      {"dds.sec.auth.library.path", plugin_library(s, "auth").string()},
      {"dds.sec.auth.library.init", "init_authentication"},
      {"dds.sec.auth.library.finalize", "finalize_authentication"},
      {"dds.sec.crypto.library.path", plugin_library(s, "crypto").string()},
      {"dds.sec.crypto.library.init", "init_crypto"},
      {"dds.sec.crypto.library.finalize", "finalize_crypto"},
      {"dds.sec.access.library.path", plugin_library(s, "ac").string()},
      {"dds.sec.access.library.init", "init_access_control"},
      {"dds.sec.access.library.finalize", "finalize_access_control"},
      {"dds.sec.auth.identity_ca", file(s.identity_ca)},
      {"dds.sec.auth.identity_certificate", file(s.certificate)},
      {"dds.sec.auth.private_key", file(s.private_key)},
      {"dds.sec.access.permissions_ca", file(s.permissions_ca)},
      {"dds.sec.access.governance", file(s.governance)},
      {"dds.sec.access.permissions", file(s.permissions)},
  };
}

}  // namespace dnbridge::security
