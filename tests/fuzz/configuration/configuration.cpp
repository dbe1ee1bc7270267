// The configuration readers (adapters/toml_config/reader.hpp and the three files
// read with it) on any text. Input: [selector] then the file's text;
// selector % 3: 0 a rack configuration (dnbridge), 1 a device configuration
// (cdn127-sim), 2 a [security] table.
// Properties: a reader never fails other than with its own error, which
// names a place in the file for every problem; a rack configuration it
// accepts, the master accepts too: every port's scan list builds a scanner
// (rack::PumpRack::scanner_config and devicenet::Scanner throw for one that
// cannot work); a device configuration it accepts gives each device its
// options.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "adapters/daemon/config.hpp"
#include "adapters/security/toml_settings.hpp"
#include "adapters/sim/host/device_config.hpp"
#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/rack/pump_rack.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;

namespace {

class NullSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame&, TimePoint) override {}
};

// "SOURCE:LINE:COLUMN: text", line and column from 1.
bool placed(const std::string& problem, std::string_view source) {
  if (problem.rfind(std::string(source) + ":", 0) != 0) return false;
  std::size_t at = source.size() + 1;
  for (int field = 0; field < 2; ++field) {
    const std::size_t digits_from = at;
    while (at < problem.size() && problem[at] >= '0' && problem[at] <= '9') ++at;
    if (at == digits_from || at >= problem.size() || problem[at] != ':') return false;
    if (problem[digits_from] == '0') return false;
    ++at;
  }
  return true;
}

void rack_configuration(std::string_view text) {
  daemon::DaemonConfig config;
  try {
    config = daemon::parse_config(text, "rack.toml");
  } catch (const daemon::ConfigError& e) {
    FUZZ_CHECK(!e.problems().empty());
    for (const auto& p : e.problems()) FUZZ_CHECK(placed(p, "rack.toml"));
    return;
  }
  FUZZ_CHECK(!config.rack.empty());
  FUZZ_CHECK(!config.ports.empty());
  for (const auto& w : config.warnings) FUZZ_CHECK(placed(w, "rack.toml"));
  for (const auto& port : config.ports) {
    const auto pumps = daemon::to_pump_configs(port);
    const auto scanner_config =
        rack::PumpRack::scanner_config(daemon::to_scanner_config(port, "fuzz-host"), pumps);
    NullSink sink;
    devicenet::ScannerObserver observer;
    devicenet::Scanner scanner(scanner_config, sink, observer, Logger());
    rack::PumpRack pump_rack(pumps);
  }
}

void devices(std::string_view text) {
  sim::host::DeviceConfig config;
  try {
    config = sim::host::parse_device_config(text, "devices.toml");
  } catch (const sim::host::DeviceConfigError& e) {
    FUZZ_CHECK(!e.problems().empty());
    for (const auto& p : e.problems()) FUZZ_CHECK(placed(p, "devices.toml"));
    return;
  }
  const auto options = sim::host::device_options({}, config, sim::host::Reading::kLenient);
  FUZZ_CHECK(options.size() == config.devices.size());
  for (const auto& o : options) (void)sim::host::describe_readings(o.cdn127);
}

void security_table(std::string_view text) {
  toml_config::Problems problems("security.toml");
  const auto root = toml_config::parse(text, problems);
  if (root) {
    const toml::node* n = root->get("security");
    if (n == nullptr) return;
    const auto settings = security::read_table(*n, problems);
    FUZZ_CHECK(settings.has_value() != problems.has_errors());
  }
  for (const auto& p : problems.errors()) FUZZ_CHECK(placed(p, "security.toml"));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  switch (data[0] % 3) {
    case 0:
      rack_configuration(text);
      break;
    case 1:
      devices(text);
      break;
    default:
      security_table(text);
      break;
  }
  return 0;
}
