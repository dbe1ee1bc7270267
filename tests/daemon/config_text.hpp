#pragma once
// What the rack-file tests share: the first lines of most of their texts,
// and the problems a text is refused with.
#include <filesystem>
#include <string>
#include <string_view>

#include "adapters/daemon/config.hpp"

// Lines 1..5 of most texts: a rack with one simulated port.
#define ONE_PORT                \
  "rack = \"r\"\n"              \
  "[[port]]\n"                  \
  "name = \"A\"\n"              \
  "interface = \"simulated\"\n" \
  "bitrate = 500000\n"

namespace dnbridge::daemon::config_test {

// The problems parse_config reports for `text` (EDS files named relative to
// `base`), one per line, or "(none)".
inline std::string problems(std::string_view text,
                            const std::filesystem::path& base = DNBRIDGE_EDS_DIR) {
  try {
    parse_config(text, "t.toml", base);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(none)";
}

inline devicenet::MacId mac(unsigned v) { return devicenet::MacId::from(v).value(); }

}  // namespace dnbridge::daemon::config_test
