#pragma once
// The DDS Security of one participant (dnbridge's or dnbctl's): the files the
// OMG DDS Security built-in plugins take, and where Cyclone DDS's plugin
// libraries are. Read from a [security] table (toml_settings.hpp), checked
// before a participant is made (check.hpp), and handed to Cyclone DDS as
// participant QoS properties, which take precedence over any security
// section of the Cyclone XML configuration (CYCLONEDDS_URI).
#include <filesystem>
#include <string_view>

#include "adapters/dds/participant.hpp"

namespace dnbridge::security {

struct Settings {
  std::filesystem::path identity_ca;     // PEM: the CA that signs every identity of the site
  std::filesystem::path certificate;     // PEM: this participant's identity, signed by identity_ca
  std::filesystem::path private_key;     // PEM: the certificate's key, not encrypted
  std::filesystem::path permissions_ca;  // PEM: the CA that signs the two documents
  std::filesystem::path governance;      // S/MIME, signed by permissions_ca
  std::filesystem::path permissions;     // S/MIME, signed by permissions_ca
  // libdds_security_{auth,ac,crypto}.so; empty: by name, on the loader's search path.
  std::filesystem::path plugin_directory = default_plugin_directory();

  // Where the build found Cyclone DDS's security plugins (Debian:
  // /usr/lib/<multiarch>/libddsc0debian, not on the loader's search path).
  static std::filesystem::path default_plugin_directory();

  // Relative paths are taken relative to `directory` (the directory of the
  // file they were read from).
  void resolve_relative_to(const std::filesystem::path& directory);
};

// The plugin library of one of Cyclone's three security plugins ("auth",
// "ac", "crypto"): a path in the plugin directory, or the plugin's name.
std::filesystem::path plugin_library(const Settings& settings, std::string_view plugin);

// Cyclone DDS's participant QoS properties for `settings` (dds.sec.*): the
// files as file: URIs, the three plugin libraries and their entry points.
dds::Properties participant_properties(const Settings& settings);

}  // namespace dnbridge::security
