#pragma once
// cdn127-sim's device configuration (--device-config FILE, TOML): for each
// simulated device, the readings of the CDN127 manual it takes, as field
// devices differ, and the output fault/idle actions it leaves the factory
// with (sim::SlaveOptions documents each).
//
//   [defaults]                  # every device, those given only with --mac too
//   explicit_response_delay_ms = 300
//
//   [[device]]                  # one device, simulated even without --mac
//   mac = 5
//   poll_paths_fixed = true
//
// A [[device]] with `eds = "FILE"` (relative to the configuration's
// directory) is not a CDN127 but a device driven by that EDS file
// (sim::EdsSlave: Identity, Assembly, Parameter, Acknowledge Handler, poll
// and change-of-state or cyclic production); the CDN127's keys below are
// not for it, and [defaults] does not reach it. Its other keys:
//   serial_number = 0..0xFFFFFFFF   (default: the simulator's, from its MAC)
//   member_lists = true|false       false: Assembly attributes 1 and 2 answer
//                                   0x14 (a device that describes its
//                                   assemblies only in its EDS)
//
// Keys of [defaults] and CDN127 [[device]]s (all optional; mac required in,
// and only in, [[device]]):
//   configuration_locked_while_poll_allocated = true|false
//   poll_paths_fixed = true|false
//   idle_poll_answered_empty = true|false
//   no_ack_of_last_request_fragment = true|false
//   release_keeps_outputs = true|false
//   explicit_response_delay_ms = 0..60000
//   poll_response_delay_ms = 0..60000
//   serial_number_bytes = 2|4
//   identity_state_supported = true|false
//   epr_resolution_ms = 1..65535
//   unsafe_factory_output_actions = true|false
// deploy/config/cdn127-sim-example.toml is an annotated example.
//
// A device's options: sim::default_slave_options(mac), then the --reading
// preset, then [defaults], then its [[device]] table; each layer changes
// only what it names.
//
// Set-up code at the edge: the reader throws DeviceConfigError, with every
// problem as "FILE:LINE:COLUMN: what is wrong".
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/sim/cdn127/cdn127_device.hpp"
#include "adapters/sim/generic/eds_slave.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::sim::host {

// What one table sets; what it leaves unset stays as the layer below has it.
struct DeviceSettings {
  std::optional<bool> configuration_locked_while_poll_allocated;
  std::optional<bool> poll_paths_fixed;
  std::optional<bool> idle_poll_answered_empty;
  std::optional<bool> no_ack_of_last_request_fragment;
  std::optional<bool> release_keeps_outputs;
  std::optional<Duration> explicit_response_delay;
  std::optional<Duration> poll_response_delay;
  std::optional<bool> serial_number_udint;       // serial_number_bytes = 4
  std::optional<bool> identity_state_supported;  // false: Identity attribute 8 answers 0x14
  std::optional<Duration> epr_resolution;        // SlaveOptions::timer_resolution
  // SlaveOptions::factory_output_actions: true sim::kUnsafeFactoryOutputActions,
  // false the simulator's default.
  std::optional<bool> unsafe_factory_output_actions;

  void apply_to(sim::SlaveOptions& options) const;
};

// A device driven by an EDS file.
struct EdsDevice {
  std::string path;  // as resolved, for the log
  std::shared_ptr<const profiles::eds::EdsFile> file;
  std::optional<std::uint32_t> serial_number;
  bool member_lists = true;
};

struct DeviceEntry {
  devicenet::MacId mac;
  DeviceSettings settings;
  std::optional<EdsDevice> eds;
};

struct DeviceConfig {
  DeviceSettings defaults;
  std::vector<DeviceEntry> devices;  // in the file's order, each MAC once
};

// --reading: the simulator's own reading, or every field reading at once
// (sim::apply_field_reading).
enum class Reading : std::uint8_t { kLenient, kField };

class DeviceConfigError : public std::runtime_error {
 public:
  explicit DeviceConfigError(std::vector<std::string> problems);
  const std::vector<std::string>& problems() const noexcept { return problems_; }

 private:
  std::vector<std::string> problems_;
};

// Parses and checks a device configuration; `source_name` names it in
// messages, EDS files are found relative to `base_dir`. Throws
// DeviceConfigError.
DeviceConfig parse_device_config(std::string_view text, std::string_view source_name,
                                 const std::filesystem::path& base_dir = {});
// Reads and checks a device configuration file. Throws DeviceConfigError.
DeviceConfig load_device_config(const std::filesystem::path& path);

// One device to simulate: a CDN127 with its options, or a device driven by
// an EDS file.
struct DeviceSpec {
  sim::SlaveOptions cdn127;
  std::optional<EdsDevice> eds;
  sim::EdsSlaveOptions eds_options;  // with `eds`
};

// The devices to simulate: those given with --mac, in that order, then those
// only the file names, in its order; each with its options as the header
// says. A MAC given both ways is one device.
std::vector<DeviceSpec> device_options(const std::vector<devicenet::MacId>& macs,
                                       const DeviceConfig& config, Reading reading);

// The readings a device takes, and its factory output actions when they
// are not the default, for the log: "lenient" when it has none of them, else
// a comma-separated list ("configuration locked while poll allocated,
// explicit responses 300 ms late, ...").
std::string describe_readings(const sim::SlaveOptions& options);

}  // namespace dnbridge::sim::host
