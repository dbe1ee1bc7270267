#pragma once
// `dnbridge-sim --simulate`'s configuration, the embedded default (rack
// "sim-rack", port A with pumps 1..8 on the simulated bus), as the text a
// test changes and writes to a file for a bridge process.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "adapters/daemon/config.hpp"

namespace dnbridge::support {

// The first `from` in `text` replaced by `to`; throws if there is none (the
// default no longer has the line a test changes).
inline void replace_first(std::string& text, std::string_view from, std::string_view to) {
  const auto at = text.find(from);
  if (at == std::string::npos) {
    throw std::logic_error("the embedded default configuration has no \"" + std::string(from) +
                           "\"");
  }
  text.replace(at, from.size(), to);
}

// The embedded default as rack `rack` on DDS domain `domain`, logging at
// `log_level`.
inline std::string simulated_rack_config(std::int64_t domain, std::string_view rack = "sim-rack",
                                         std::string_view log_level = "info") {
  std::string text(daemon::embedded_default_config_text());
  replace_first(text, "rack = \"sim-rack\"", "rack = \"" + std::string(rack) + "\"");
  replace_first(text, "domain = 0", "domain = " + std::to_string(domain));
  replace_first(text, "log_level = \"info\"", "log_level = \"" + std::string(log_level) + "\"");
  return text;
}

// A [[port.node]] of the last [[port]]: the example I/O block of
// deploy/eds at MAC 20 ("io-1"), on change of state, its safe state every
// output off; `source_dir` is the source tree's.
inline std::string example_io_block_node(std::string_view source_dir) {
  std::string text =
      "  [[port.node]]\n  mac = 20\n  name = \"io-1\"\n  profile = \"eds\"\n  eds = \"";
  text += source_dir;
  text +=
      "/deploy/eds/dnbridge-example-io-block.eds\"\n"
      "  connection = \"change-of-state\"\n"
      "  safe_state_parameters = [ { name = \"Output fault action\", value = 0 },\n"
      "                 { name = \"Output fault value\", value = 0 },\n"
      "                 { name = \"Output idle action\", value = 0 },\n"
      "                 { name = \"Output idle value\", value = 0 } ]\n";
  return text;
}

}  // namespace dnbridge::support
