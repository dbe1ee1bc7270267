#pragma once
// The [security] table, as dnbridge's rack configuration and dnbctl's
// --security file both hold it:
//
//   [security]
//   identity_ca = "identity_ca.pem"
//   certificate = "cert.pem"
//   private_key = "key.pem"
//   permissions_ca = "permissions_ca.pem"
//   governance = "governance.p7s"
//   permissions = "permissions.p7s"
//   plugins = "/usr/lib/x86_64-linux-gnu/libddsc0debian"   # optional
//
// Every key but `plugins` is required; relative paths are relative to the
// directory of the file the table is in.
#include <toml++/toml.h>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/security/settings.hpp"
#include "adapters/toml_config/reader.hpp"

namespace dnbridge::security {

// Reads the value of a `security` key. Paths are kept as written:
// Settings::resolve_relative_to takes them from the file's directory. Adds
// what is wrong to `problems`; nullopt when anything is. `allowed`, when
// given, is the table of the keys the file documents (TableReader::allow_only).
std::optional<Settings> read_table(const toml::node& node, toml_config::Problems& problems,
                                   std::vector<std::string_view> allowed = {});

// A file whose [security] table is wrong, or absent: every problem,
// "FILE:LINE:COLUMN: text", one per line.
class SettingsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The [security] table of a TOML file (other tables are not looked at, so
// a rack configuration with a [security] table is such a file too), its
// paths resolved. Throws SettingsError.
Settings load_file(const std::filesystem::path& file);

}  // namespace dnbridge::security
