#pragma once
// The configuration of one rack's dnbridge daemon: the rack's name, its DDS
// domain, its DeviceNet ports and the nodes each port's master scans, read
// from a TOML file (deploy/config/rack-example.toml shows every key).
//
// Set-up code at the edge: the loader throws ConfigError. The model is plain
// values, complete once loaded (every default resolved).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/dds/topics.hpp"
#include "adapters/security/settings.hpp"
#include "adapters/socketcan/socketcan_backend.hpp"
#include "bridge/common/log.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/scan_list.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"
#include "bridge/profiles/eds/node_profile.hpp"
#include "bridge/rack/device_rack.hpp"
#include "bridge/rack/explicit_policy.hpp"
#include "bridge/rack/publish_gate.hpp"
#include "bridge/rack/pump_rack.hpp"
#include "bridge/rack/rack_port.hpp"

namespace dnbridge::daemon {

// Publishing and the no-commander policy are the rack model's.
using PublishPolicy = rack::PublishPolicy;
using NoCommanderPolicy = rack::NoCommanderPolicy;

std::string_view to_string(NoCommanderPolicy policy) noexcept;  // "idle", "hold"

// A node of the scan list as the configuration gives it, filled by the
// loader with every default resolved, and how its samples are published.
// Profile "cdn127": the rack model's own PumpConfig (its node's MAC, name
// and timings, its I/O configuration, identity, no-commander and resume
// policies, safe state). Profile "eds": the same PumpConfig's node and
// policies, and the EDS file read with the node's settings from it.
struct NodeSettings {
  rack::PumpConfig pump = cdn127_pump();
  PublishPolicy publish;
  std::string profile = "cdn127";  // or "eds"

  // Profile "eds".
  std::shared_ptr<const profiles::eds::EdsFile> eds;
  std::string eds_path;             // as resolved (absolute, or relative to the working directory)
  std::uint64_t eds_digest = 0;     // of its text
  profiles::eds::EdsNode eds_node;  // connection, parameters, safe state

  bool is_eds() const noexcept { return profile == "eds"; }
  // Profile "eds" as the rack model takes it.
  rack::DeviceConfig device() const;

  // A CDN127 with the rack model's defaults.
  static rack::PumpConfig cdn127_pump();
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
  // The port's master as the core takes it: its MAC (the rack's unless the
  // port gives its own), the vendor ID of its duplicate MAC ID check (0 by
  // default: dnbridge has no ODVA vendor ID of its own; a site may set its
  // integrator's) and its timings. The scan list and the serial number are
  // left to to_scanner_config.
  devicenet::ScannerConfig master;
  // Unset: derived from the host's identifier and the port's name
  // (host_identity.hpp), so that bridges on one bus differ.
  std::optional<std::uint32_t> master_serial_number;
  std::vector<NodeSettings> nodes;
  // The port's command_refresh_ms, for its nodes that give none of their
  // own (else [defaults]'s, else off).
  std::optional<Duration> command_refresh;
  // interface = "simulated" only: simulated CDN127s on the bus at MACs the
  // configuration does not have (simulated_unconfigured = [17]), as a
  // device with its MAC switch set wrong would be.
  std::vector<devicenet::MacId> simulated_unconfigured;
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
  // The longest liveliness lease a command writer may offer
  // (max_commander_lease_ms): the longest a commander that froze, or whose
  // host stalled or was cut off, holds the outputs it commands. A writer
  // offering a longer lease, or an infinite one, does not command.
  Duration max_commander_lease = dds::kDefaultMaxCommanderLease;
  // DDS Security of the bridge's participant ([security]); none: Cyclone's
  // XML configuration decides (CYCLONEDDS_URI), by default no security.
  std::optional<security::Settings> security;
  // Where the Prometheus metrics are served ([metrics] listen, "HOST:PORT",
  // IPv4); none: no metrics endpoint.
  std::optional<std::string> metrics_listen;
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
// and in DaemonConfig::source. Relative EDS paths are taken from `base_dir`
// (the working directory when empty). Throws ConfigError.
DaemonConfig parse_config(std::string_view text, std::string_view source_name,
                          const std::filesystem::path& base_dir = {});

// What `dnbridge-sim --simulate` runs: rack "sim-rack", eight CDN127 pumps on a
// simulated 500 kbit/s port. The text is what --print-default-config prints.
std::string_view embedded_default_config_text() noexcept;
DaemonConfig embedded_default_config();

// The scan-list entries of the port's nodes, by profile, as the rack models
// take them; each node's scan-list profile is filled by
// rack::RackPort::scan_list.
rack::PortNodes to_port_nodes(const PortConfig& port);
// Its CDN127 nodes only.
std::vector<rack::PumpConfig> to_pump_configs(const PortConfig& port);

// The port's master: MAC, duplicate MAC identity and timings. The nodes are
// left empty: rack::RackPort::scan_list(to_scanner_config(...),
// to_port_nodes(port)) fills them. The loader has already resolved what
// the port takes from the rack (the master MAC). `host_id` (read_host_id())
// gives the master's serial number where the port sets none.
devicenet::ScannerConfig to_scanner_config(const PortConfig& port, std::string_view host_id);

}  // namespace dnbridge::daemon
