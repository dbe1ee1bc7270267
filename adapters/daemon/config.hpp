#pragma once
// The configuration of one rack's dnbridge daemon: the rack's name, its DDS
// domain, its DeviceNet ports and the nodes each port's master scans, read
// from a TOML file (deploy/config/rack-example.toml shows every key).
//
// Set-up code at the edge: the loader throws ConfigError. The model is plain
// values, complete once loaded (every default resolved).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/security/settings.hpp"
#include "adapters/socketcan/socketcan_backend.hpp"
#include "bridge/common/log.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/mac_id.hpp"
#include "bridge/devicenet/scan_list.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"
#include "bridge/rack/explicit_policy.hpp"
#include "bridge/rack/publish_gate.hpp"
#include "bridge/rack/pump_rack.hpp"

namespace dnbridge::daemon {

// Publishing and the no-commander policy are the rack model's.
using PublishPolicy = rack::PublishPolicy;
using NoCommanderPolicy = rack::NoCommanderPolicy;

std::string_view to_string(NoCommanderPolicy policy) noexcept;  // "idle", "hold"

struct NodeSettings {
  devicenet::MacId mac;
  std::string name;
  std::string profile = "cdn127";  // the only device profile there is
  profiles::cdn127::IoConfiguration io =
      profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn127);
  // The identity the device must show; the CDN127's when not given.
  std::optional<devicenet::ExpectedIdentity> identity;
  Duration poll_period = devicenet::NodeConfig{}.poll_period;
  Duration expected_packet_rate = devicenet::NodeConfig{}.expected_packet_rate;
  Duration explicit_packet_rate = devicenet::NodeConfig{}.explicit_packet_rate;
  bool immediate_poll_on_change = devicenet::NodeConfig{}.immediate_poll_on_change;
  // At most the poll period; the built-in value is cut to a shorter one.
  Duration immediate_poll_min_gap = devicenet::NodeConfig{}.immediate_poll_min_gap;
  PublishPolicy publish;
  NoCommanderPolicy no_commander = NoCommanderPolicy::kIdle;
  // The outputs' fault and idle actions downloaded at start-up (off, 0 V), or
  // the device's own kept (safe_state = "device").
  profiles::cdn127::SafeStateConfig safe_state;
  // After a loss: idle until a new command (the default), or the last
  // command again (resume = "last-command").
  rack::ResumePolicy resume = rack::ResumePolicy::kFreshCommand;
  // The serial number the device must have (a swapped module or a misset
  // MAC switch is then a wrong device); without it the first one seen is
  // recorded and a change warned of.
  std::optional<std::uint32_t> serial_number;
  // For a slow device: its own timeouts, else the port's.
  std::optional<Duration> explicit_response_timeout;
  std::optional<Duration> poll_response_timeout;
};

// The master's timings on one port; defaults are devicenet::ScannerConfig's.
struct ScannerTimings {
  Duration allocate_retry_min = devicenet::ScannerConfig{}.allocate_retry_min;
  Duration allocate_retry_max = devicenet::ScannerConfig{}.allocate_retry_max;
  Duration fault_recheck = devicenet::ScannerConfig{}.fault_recheck;
  Duration poll_response_timeout = devicenet::ScannerConfig{}.poll_response_timeout;
  Duration explicit_response_timeout =
      devicenet::ScannerConfig{}.explicit_messaging.response_timeout;
  unsigned max_consecutive_errors = devicenet::ScannerConfig{}.max_consecutive_errors;
  Duration poll_batch_window = devicenet::ScannerConfig{}.poll_batch_window;
};

// The interface name of the in-process simulated bus.
inline constexpr std::string_view kSimulatedInterface = "simulated";

// Who brings a CAN controller back after bus-off.
using BusOffRecovery = socketcan::BusOffRecovery;

struct PortConfig {
  std::string name;                // DDS key of the port's samples
  std::string interface;           // kSimulatedInterface, or a SocketCAN interface (can0, ...)
  std::uint32_t bitrate = 500000;  // 125000, 250000 or 500000
  BusOffRecovery bus_off_recovery = BusOffRecovery::kInterface;  // SocketCAN only
  devicenet::MacId master_mac;  // the rack's unless the port gives its own
  // Sent in the duplicate MAC ID check of the master's MAC. dnbridge has no
  // ODVA vendor ID of its own, so the vendor defaults to 0; a site may set
  // its integrator's.
  std::uint16_t master_vendor_id = 0;
  // Unset: derived from the host's identifier and the port's name
  // (host_identity.hpp), so that bridges on one bus differ.
  std::optional<std::uint32_t> master_serial_number;
  ScannerTimings timings;
  std::vector<NodeSettings> nodes;
};

struct DaemonConfig {
  std::string rack;             // DDS key of every sample of this daemon
  std::uint32_t domain_id = 0;  // DDS domain
  devicenet::MacId master_mac;  // default master MAC of the ports
  std::vector<PortConfig> ports;
  LogLevel log_level = LogLevel::kInfo;
  // What remote requesters may do through the explicit gateway of every
  // port ([explicit_policy]); by default, nothing that takes a node's
  // connections, outputs or configuration from the bridge.
  rack::ExplicitPolicy explicit_policy;
  // DDS Security of the bridge's participant ([security]); none: Cyclone's
  // XML configuration decides (CYCLONEDDS_URI), by default no security.
  std::optional<security::Settings> security;
  std::string source;  // the file it came from, or "embedded default"
  // Things that load but look wrong, "FILE:LINE:COLUMN: text", for the log.
  std::vector<std::string> warnings;
};

// One or more problems in a configuration, each "FILE:LINE:COLUMN: what is
// wrong" (lines and columns from 1), sorted by position; what() has them one
// per line.
class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(std::vector<std::string> problems);
  const std::vector<std::string>& problems() const noexcept { return problems_; }

 private:
  std::vector<std::string> problems_;
};

// Reads and checks a configuration file. Throws ConfigError.
DaemonConfig load_config_file(const std::filesystem::path& path);

// Parses and checks configuration text; `source_name` names it in messages
// and in DaemonConfig::source. Throws ConfigError.
DaemonConfig parse_config(std::string_view text, std::string_view source_name);

// What `dnbridge-sim --simulate` runs: rack "sim-rack", eight CDN127 pumps on a
// simulated 500 kbit/s port. The text is what --print-default-config prints.
std::string_view embedded_default_config_text() noexcept;
DaemonConfig embedded_default_config();

// The scan-list entry of a node and the I/O configuration its data is decoded
// with; the node's profile is filled by rack::PumpRack::scanner_config.
rack::PumpConfig to_pump_config(const NodeSettings& node);
std::vector<rack::PumpConfig> to_pump_configs(const PortConfig& port);

// The port's master: MAC, duplicate MAC identity and timings. The nodes are
// left empty: rack::PumpRack::scanner_config(to_scanner_config(...),
// to_pump_configs(port)) fills them. The loader has already resolved what
// the port takes from the rack (the master MAC). `host_id` (read_host_id())
// gives the master's serial number where the port sets none.
devicenet::ScannerConfig to_scanner_config(const PortConfig& port, std::string_view host_id);

}  // namespace dnbridge::daemon
