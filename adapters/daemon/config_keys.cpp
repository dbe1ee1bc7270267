// The rack file's key table and what is derived from it: the allowed keys
// per place, the messages for a key in the wrong place or of another
// profile, and dnbridge.toml(5)'s key reference.
#include "adapters/daemon/config_keys.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <stdexcept>

#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::daemon {
namespace {

using P = KeyPlace;
using R = OnReload;
constexpr std::uint8_t kCdn = kCdn127Nodes;
constexpr std::uint8_t kEds = kEdsNodes;
constexpr std::uint8_t kAll = kEveryProfile;

// clang-format off
constexpr std::array kKeys = std::to_array<ConfigKey>({
  // The top level.
  {"rack", P::kTop, "string", words("no '*', '?' or control character"), "required", R::kRestart,
   "The rack's name: the rack key of everything it publishes, and its DDS partition dnbridge/RACK."},
  {"domain", P::kTop, "integer", {0, kMaxDomainId, {}}, "0", R::kRestart,
   "The DDS domain ID."},
  {"master_mac", P::kTop, "integer", {0, devicenet::MacId::kMax, {}}, "0", R::kRestart,
   "The master's DeviceNet MAC ID on every port that gives none of its own; no node may use it."},
  {"max_commander_lease_ms", P::kTop, "integer, ms", {kMinCommanderLeaseMs, kMaxCommanderLeaseMs, {}}, "10000", R::kRestart,
   "The longest liveliness lease a command writer may offer: a writer offering more, or an infinite one, does not command."},
  {"log_level", P::kTop, "string", words("\"trace\", \"debug\", \"info\", \"warn\" or \"error\""), "\"info\"", R::kApplied,
   "The least important messages logged."},
  {"defaults", P::kTop, "table", {}, "none", R::kByItsKeys,
   "[defaults]: node keys every [[port.node]] takes unless it gives its own."},
  {"port", P::kTop, "array of tables", words("at least one"), "required", R::kByItsKeys,
   "[[port]]: one DeviceNet port (CAN interface) of the rack; a port added or removed needs a restart."},
  {"explicit_policy", P::kTop, "table", {}, "none", R::kByItsKeys,
   "[explicit_policy]: what a remote requester may do to a node through explicit messaging."},
  {"metrics", P::kTop, "table", {}, "none (off)", R::kRestart,
   "[metrics]: the Prometheus endpoint."},
  {"security", P::kTop, "table", {}, "none (off)", R::kRestart,
   "[security]: the bridge's DDS Security identity and the site's signed documents."},

  // [explicit_policy]: the names are rack::policy_key's.
  {"allow_allocate_release", P::kExplicitPolicy, "boolean", {}, "false", R::kApplied,
   "Allocate and Release of the DeviceNet object."},
  {"allow_connection_changes", P::kExplicitPolicy, "boolean", {}, "false", R::kApplied,
   "Set and the other changing services of the Connection object."},
  {"allow_output_writes", P::kExplicitPolicy, "boolean", {}, "false", R::kApplied,
   "Set of an output point's value or of assembly data: it bypasses the commands' ownership."},
  {"allow_managed_attribute_writes", P::kExplicitPolicy, "boolean", {}, "false", R::kApplied,
   "Set of an attribute the bridge configures (Configuration object, the outputs' fault and idle settings)."},
  {"allow_identity_reset", P::kExplicitPolicy, "boolean", {}, "false", R::kApplied,
   "Reset of the Identity object: the device restarts."},
  {"allow_network_settings", P::kExplicitPolicy, "boolean", {}, "false", R::kApplied,
   "Set of the DeviceNet object: MAC ID, bit rate, bus-off interrupt."},
  {"allow_other_services", P::kExplicitPolicy, "boolean", {}, "false", R::kApplied,
   "Any other service (Multiple_Service_Packet, Start, Stop, Save, Restore, vendor services)."},

  // [metrics]
  {"listen", P::kMetrics, "string", words("\"HOST:PORT\", IPv4 or a host name"), "required", R::kRestart,
   "Where the bridge serves http://LISTEN/metrics; the endpoint has no authentication."},

  // [security]: the names are security::read_table's.
  {"identity_ca", P::kSecurity, "string, a path", {}, "required", R::kRestart,
   "The identity CA's certificate; a relative path is relative to the file's directory."},
  {"certificate", P::kSecurity, "string, a path", {}, "required", R::kRestart,
   "The bridge's identity certificate."},
  {"private_key", P::kSecurity, "string, a path", {}, "required", R::kRestart,
   "The bridge's private key."},
  {"permissions_ca", P::kSecurity, "string, a path", {}, "required", R::kRestart,
   "The permissions CA's certificate."},
  {"governance", P::kSecurity, "string, a path", {}, "required", R::kRestart,
   "The signed governance document."},
  {"permissions", P::kSecurity, "string, a path", {}, "required", R::kRestart,
   "The bridge's signed permissions document."},
  {"plugins", P::kSecurity, "string, a path", {}, "where dnbridge was built to find them", R::kRestart,
   "The directory of Cyclone DDS's security plugins."},

  // [[port]]
  {"name", P::kPort, "string", words("unique in the rack"), "required", R::kRestart,
   "The port's name: the port key of what it publishes; another name is another port."},
  {"interface", P::kPort, "string", words("a SocketCAN name (at most 15 characters) or \"simulated\""), "required", R::kRestart,
   "The CAN interface; two ports may not share one."},
  {"bitrate", P::kPort, "integer, bit/s", words("125000, 250000 or 500000"), "required", R::kRestart,
   "The bus's bit rate."},
  {"bus_off_recovery", P::kPort, "string", words("\"interface\", \"restart\" or \"report\""), "\"interface\"", R::kRestart,
   "Who brings the CAN controller back after bus-off: the interface itself, dnbridge, or nobody (reported)."},
  {"master_mac", P::kPort, "integer", {0, devicenet::MacId::kMax, {}}, "the rack's master_mac", R::kRestart,
   "This port's master MAC ID."},
  {"master_vendor_id", P::kPort, "integer", {0, 0xFFFF, {}}, "0", R::kRestart,
   "The master's vendor ID in the duplicate MAC ID check."},
  {"master_serial_number", P::kPort, "integer", {0, 0xFFFF'FFFF, {}}, "derived from /etc/machine-id and the port's name", R::kRestart,
   "The master's serial number in the duplicate MAC ID check."},
  {"allocate_retry_min_ms", P::kPort, "integer, ms", {1, kMaxPublishPeriodMs, {}}, "250", R::kApplied,
   "The first retry of an absent node, doubling up to allocate_retry_max_ms."},
  {"allocate_retry_max_ms", P::kPort, "integer, ms", {1, kMaxPublishPeriodMs, "not below allocate_retry_min_ms"}, "5000", R::kApplied,
   "The longest retry of an absent node."},
  {"fault_recheck_ms", P::kPort, "integer, ms", {1, kMaxPublishPeriodMs, {}}, "10000", R::kApplied,
   "How often a wrong device or a faulted node is checked again."},
  {"poll_response_timeout_ms", P::kPort, "integer, ms", {1, kMaxPublishPeriodMs, {}}, "50", R::kApplied,
   "A poll response later than this is lost."},
  {"explicit_response_timeout_ms", P::kPort, "integer, ms", {1, kMaxPublishPeriodMs, {}}, "2000", R::kApplied,
   "An explicit response later than this is lost."},
  {"scan_response_timeout_ms", P::kPort, "integer, ms", {1, kMaxPublishPeriodMs, {}}, "1000", R::kApplied,
   "A bus scan's wait for each answer of a node it asks (dnbctl scan)."},
  {"poll_batch_ms", P::kPort, "integer, ms", {0, kMaxPollBatchMs, {}}, "2", R::kApplied,
   "Polls due within this of one sent now go with it, early (at most a quarter period); 0 keeps exact slots."},
  {"max_consecutive_errors", P::kPort, "integer", {1, 1000, {}}, "10", R::kApplied,
   "Bad poll responses in a row before the node is connected again."},
  {"command_refresh_ms", P::kPort, "integer, ms", {0, kMaxCommandRefreshMs, "0 is off, else at least 50"}, "[defaults]'", R::kApplied,
   "The command refresh of this port's nodes that give none of their own."},
  {"simulated_unconfigured", P::kPort, "array of MAC IDs", words("for interface = \"simulated\""), "none", R::kRestart,
   "Simulated CDN127s at MACs no node has, as devices with a misset MAC switch."},
  {"node", P::kPort, "array of tables", {}, "none (the port scans nothing)", R::kByItsKeys,
   "[[port.node]]: a node of the port."},

  // [[port.node]], and [defaults] where in_defaults.
  {"mac", P::kNode, "integer", {0, devicenet::MacId::kMax, "unique on the port, not the master's"}, "required", R::kReconfigured,
   "The node's DeviceNet MAC ID; another MAC is another node.", kAll, false},
  {"name", P::kNode, "string", words("unique on the port"), "required", R::kApplied,
   "The name operators see (the pump's tag).", kAll, false},
  {"serial", P::kNode, "integer", {0, 0xFFFF'FFFF, {}}, "none (the first serial seen is recorded)", R::kReconfigured,
   "The serial number the device must have (Identity attribute 6); another is a wrong device.", kAll, false},
  {"profile", P::kNode, "string", words("\"cdn127\" or \"eds\""), "\"cdn127\"", R::kReconfigured,
   "A CDN127 pump interface (PumpState, PumpCommand) or a Group 2 slave described by its EDS file (DeviceState, DeviceCommand).", kAll, true},
  {"poll_period_ms", P::kNode, "integer, ms", {1, kMaxPacketRateMs, {}}, "100", R::kReconfigured,
   "The poll period.", kAll, true},
  {"expected_packet_rate_ms", P::kNode, "integer, ms", {1, kMaxPacketRateMs, "not below poll_period_ms"}, "1000", R::kReconfigured,
   "The poll connection's expected packet rate: 4 x this without traffic drops the connection.", kAll, true},
  {"explicit_packet_rate_ms", P::kNode, "integer, ms", {1, kMaxPacketRateMs, {}}, "2500", R::kReconfigured,
   "The explicit connection's expected packet rate; the master keeps it alive once per period.", kAll, true},
  {"immediate_poll", P::kNode, "boolean", {}, "true", R::kReconfigured,
   "Poll at once when a command changes the outputs.", kAll, true},
  {"immediate_poll_min_gap_ms", P::kNode, "integer, ms", {0, kMaxPacketRateMs, "not above poll_period_ms"}, "10, or the poll period if shorter", R::kReconfigured,
   "Polls sent at once for changed outputs come at least this far apart.", kAll, true},
  {"publish_max_period_ms", P::kNode, "integer, ms", {1, kMaxPublishPeriodMs, {}}, "1000", R::kApplied,
   "The state is published on every change and at least this often; over half the deadline offered at start it needs a restart.", kAll, true},
  {"explicit_response_timeout_ms", P::kNode, "integer, ms", {1, kMaxResponseTimeoutMs, {}}, "the port's", R::kReconfigured,
   "This node's own explicit response timeout, for a slow device.", kAll, true},
  {"poll_response_timeout_ms", P::kNode, "integer, ms", {1, kMaxResponseTimeoutMs, {}}, "the port's", R::kReconfigured,
   "This node's own poll response timeout, for a slow device.", kAll, true},
  {"no_commander", P::kNode, "string", words("\"idle\" or \"hold\""), "\"idle\"", R::kApplied,
   "What the outputs do when no supervisor commands the node any more.", kAll, true},
  {"command_refresh_ms", P::kNode, "integer, ms", {0, kMaxCommandRefreshMs, "0 is off, else at least 50"}, "the port's, else [defaults]', else 0", R::kApplied,
   "A commander must write the node's command at least this often, or it is no longer in force.", kAll, true},
  {"resume", P::kNode, "string", words("\"new-command\" or \"last-command\""), "\"new-command\"", R::kApplied,
   "After a loss the outputs are idle until a new command, or (unsafe, warned of) the last command drives them again.", kAll, true},
  {"safe_state", P::kNode, "string", words("\"configured\" or \"device\""), "\"configured\"", R::kReconfigured,
   "Where the outputs' fault and idle actions come from: this file (a CDN127's pump_on_fault ..., an EDS node's safe_state_parameters), or the device's maker (\"device\": read, shown, never written).", kAll, true},
  {"io", P::kNode, "string or table", words("\"cdn127\", \"cdn118\" or { ... }"), "\"cdn127\"", R::kReconfigured,
   "The CDN127's I/O configuration (Configuration object): a preset, or a table of its values over one.", kCdn, true},
  {"identity", P::kNode, "table", words("{ vendor_id, product_type, product_code }"), "59, 27, 1888", R::kReconfigured,
   "The identity the device must show (Identity attributes 1..3); another is a wrong device.", kCdn, true},
  {"analog_deadband_volts", P::kNode, "number, V", {0, 10, {}}, "0.05", R::kApplied,
   "An analog input change smaller than this does not by itself publish a sample.", kCdn, true},
  {"pump_on_fault", P::kNode, "string", words("\"off\", \"on\" or \"hold\""), "\"off\"", R::kReconfigured,
   "The pump output on a fault (4 x the expected packet rate without polls).", kCdn, true},
  {"pump_on_idle", P::kNode, "string", words("\"off\", \"on\" or \"hold\""), "\"off\"", R::kReconfigured,
   "The pump output when idle.", kCdn, true},
  {"n2_ballast_on_fault", P::kNode, "string", words("\"off\", \"on\" or \"hold\""), "\"off\"", R::kReconfigured,
   "The N2 ballast output on a fault.", kCdn, true},
  {"n2_ballast_on_idle", P::kNode, "string", words("\"off\", \"on\" or \"hold\""), "\"off\"", R::kReconfigured,
   "The N2 ballast output when idle.", kCdn, true},
  {"analog_output_on_fault", P::kNode, "number, V, or string", {0, 10, "or \"hold\""}, "0.0", R::kReconfigured,
   "The analog output on a fault.", kCdn, true},
  {"analog_output_on_idle", P::kNode, "number, V, or string", {0, 10, "or \"hold\""}, "0.0", R::kReconfigured,
   "The analog output when idle.", kCdn, true},
  {"eds", P::kNode, "string, a path", words("relative to the rack file's directory"), "required", R::kReconfigured,
   "The device's EDS file.", kEds, true},
  {"connection", P::kNode, "string", words("\"poll\", \"change-of-state\", \"cyclic\" or \"bit-strobe\", as the EDS offers"), "\"poll\"", R::kReconfigured,
   "The I/O connection the inputs come on; the outputs and the keep-alive stay on the poll connection.", kEds, true},
  {"heartbeat_ms", P::kNode, "integer, ms", {1, kMaxPacketRateMs, "change-of-state or cyclic"}, "1000", R::kReconfigured,
   "The change-of-state or cyclic connection's expected packet rate.", kEds, true},
  {"inhibit_ms", P::kNode, "integer, ms", {0, kMaxPacketRateMs, "below heartbeat_ms; change-of-state"}, "the device's", R::kReconfigured,
   "No two change-of-state messages closer than this.", kEds, true},
  {"acknowledged", P::kNode, "boolean", words("change-of-state or cyclic"), "true", R::kReconfigured,
   "The bridge acknowledges each message; false allocates with acknowledgment suppressed.", kEds, true},
  {"parameters", P::kNode, "array of { name, value }", words("the EDS's parameters, by name or \"ParamN\""), "none", R::kReconfigured,
   "EDS parameters set at start-up, in order: read, written when they differ, read back.", kEds, true},
  {"safe_state_parameters", P::kNode, "array of { name, value }", words("the EDS's parameters that set the outputs' fault and idle actions"), "none; required with outputs and safe_state = \"configured\"", R::kReconfigured,
   "The outputs' safe state: set after parameters, read back; a parameter of a fault or idle state in neither list is warned of.", kEds, true},

  // io = { ... }
  {"preset", P::kIo, "string", words("\"cdn127\" or \"cdn118\""), "\"cdn127\"", R::kReconfigured,
   "The preset the other values change."},
  {"mode", P::kIo, "integer", {0, 0xFF, {}}, "the preset's", R::kReconfigured,
   "The Mode byte: bit 7 exception status in the response, bit 2 no I/O update between request and response, bit 0 no pad bytes."},
  {"digital_inputs", P::kIo, "integer", {0, 8, {}}, "the preset's", R::kReconfigured,
   "The number of digital inputs."},
  {"digital_outputs", P::kIo, "integer", {0, 8, {}}, "the preset's", R::kReconfigured,
   "The number of digital outputs."},
  {"analog_inputs", P::kIo, "integer", {0, 2, {}}, "the preset's", R::kReconfigured,
   "The number of analog inputs."},
  {"analog_outputs", P::kIo, "integer", {0, 1, {}}, "the preset's", R::kReconfigured,
   "The number of analog outputs."},
  {"no_nc_mask", P::kIo, "integer", {0, 0xFF, {}}, "the preset's", R::kReconfigured,
   "Bit n set: digital input n+1 reads 0 when active."},

  // identity = { ... }
  {"vendor_id", P::kIdentity, "integer", {0, 0xFFFF, {}}, "required", R::kReconfigured,
   "Identity attribute 1."},
  {"product_type", P::kIdentity, "integer", {0, 0xFFFF, {}}, "required", R::kReconfigured,
   "Identity attribute 2."},
  {"product_code", P::kIdentity, "integer", {0, 0xFFFF, {}}, "required", R::kReconfigured,
   "Identity attribute 3."},

  // parameters = [ { ... } ], safe_state_parameters = [ { ... } ]
  {"name", P::kParameter, "string", words("the EDS's name, or \"ParamN\""), "required", R::kReconfigured,
   "The parameter."},
  {"value", P::kParameter, "number", words("the EDS's limits, as the device holds it"), "required", R::kReconfigured,
   "Its value."},
});
// clang-format on

std::string_view place_name(KeyPlace place) {
  switch (place) {
    case P::kTop:
      return "the top level";
    case P::kExplicitPolicy:
      return "[explicit_policy]";
    case P::kMetrics:
      return "[metrics]";
    case P::kSecurity:
      return "[security]";
    case P::kPort:
      return "[[port]]";
    case P::kNode:
      return "a [[port.node]] table";
    case P::kIo:
      return "io = { ... }";
    case P::kIdentity:
      return "identity = { ... }";
    case P::kParameter:
      return "a { name, value } of parameters or safe_state_parameters";
  }
  return "?";
}

std::string_view profile_words(std::uint8_t profiles) {
  switch (profiles) {
    case kCdn:
      return "cdn127 nodes";
    case kEds:
      return "eds nodes";
    default:
      return "every node";
  }
}

std::string_view reload_words(OnReload r) {
  switch (r) {
    case R::kApplied:
      return "a reload applies it";
    case R::kReconfigured:
      return "a reload configures the node again";
    case R::kRestart:
      return "needs a restart";
    case R::kByItsKeys:
      return "";
  }
  return "?";
}

// Literal text in roff: a backslash is \e, a minus is \- (keys and values
// copy as typed). A text line starts with \&, which keeps a leading . or '
// from being read as a request.
std::string roff(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (c == '\\') {
      out += "\\e";
    } else if (c == '-') {
      out += "\\-";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

std::span<const ConfigKey> config_keys() noexcept { return kKeys; }

const ConfigKey* config_key(KeyPlace place, std::string_view name) noexcept {
  for (const auto& k : kKeys) {
    if (k.place == place && k.name == name) return &k;
  }
  return nullptr;
}

KeyRange bounds_of(KeyPlace place, std::string_view name) {
  const ConfigKey* k = config_key(place, name);
  if (k == nullptr || !k->range.bounded()) {
    throw std::logic_error(fmt::format("the key table gives '{}' no bounds", name));
  }
  return k->range;
}

std::vector<std::string_view> key_names(KeyPlace place) {
  std::vector<std::string_view> out;
  for (const auto& k : kKeys) {
    if (k.place == place) out.push_back(k.name);
  }
  return out;
}

std::vector<std::string_view> defaults_key_names() {
  std::vector<std::string_view> out;
  for (const auto& k : kKeys) {
    if (k.place == P::kNode && k.in_defaults) out.push_back(k.name);
  }
  return out;
}

std::string misplaced_key(KeyPlace place, bool in_defaults, std::string_view key) {
  const ConfigKey* node = config_key(P::kNode, key);
  const ConfigKey* port = config_key(P::kPort, key);
  // Where a node key stands: "[defaults] or a [[port.node]] table", or "a
  // [[port.node]] table only".
  const auto node_places = [](const ConfigKey& k) {
    return k.in_defaults ? std::string("[defaults] or a [[port.node]] table")
                         : std::string("a [[port.node]] table only");
  };
  if (in_defaults) {
    if (node) return fmt::format("{} stands in a [[port.node]] table only, not in [defaults]", key);
    if (port)
      return fmt::format("{} is a port key: it stands in a [[port]] table, not in [defaults]", key);
    return {};
  }
  switch (place) {
    case P::kTop:
      if (node && port) {
        return fmt::format("{} stands in a [[port]] or [[port.node]] table, not at the top level",
                           key);
      }
      if (node)
        return fmt::format("{} is a node key: it stands in {}, not at the top level", key,
                           node_places(*node));
      if (port)
        return fmt::format("{} is a port key: it stands in a [[port]] table, not at the top level",
                           key);
      return {};
    case P::kPort:
      if (node) return fmt::format("{} is a node key: it stands in {}", key, node_places(*node));
      return {};
    case P::kNode:
      if (port) {
        return fmt::format(
            "{} is a port key: it stands in the [[port]] table, before its "
            "[[port.node]] tables",
            key);
      }
      return {};
    default:
      return {};
  }
}

std::string other_profile_key(std::uint8_t profile, std::string_view key) {
  const ConfigKey* k = config_key(P::kNode, key);
  if (k == nullptr || (k->profiles & profile) != 0) return {};
  if (k->profiles == kEds) return fmt::format("{} is for profile = \"eds\" nodes", key);
  return fmt::format("{} is a CDN127 setting: this node has profile = \"eds\"", key);
}

std::vector<std::string_view> keys_of_other_profiles(std::uint8_t profile) {
  std::vector<std::string_view> out;
  for (const auto& k : kKeys) {
    if (k.place == P::kNode && (k.profiles & profile) == 0) out.push_back(k.name);
  }
  return out;
}

std::string key_reference_roff() {
  std::string out;
  KeyPlace place{};
  bool first = true;
  for (const auto& k : kKeys) {
    if (first || k.place != place) {
      out += fmt::format(".SS {}\n", roff(place_name(k.place)));
      if (k.place == P::kNode) {
        out +=
            "Each also in \\fB[defaults]\\fR, for every node of its profiles, unless said "
            "otherwise.\n";
      }
      place = k.place;
      first = false;
    }
    out += fmt::format(".TP\n.B {}\n", roff(k.name));
    std::string facts = std::string(k.type);
    if (k.range.bounded()) facts += fmt::format("; {}..{}", k.range.min, k.range.max);
    if (!k.range.text.empty()) {
      facts += fmt::format("{} {}", k.range.bounded() ? "," : ";", k.range.text);
    }
    facts += k.fallback == "required" ? std::string("; required")
                                      : fmt::format("; default {}", k.fallback);
    if (k.reload != R::kByItsKeys) facts += fmt::format("; {}", reload_words(k.reload));
    if (k.place == P::kNode) {
      facts += fmt::format("; {}", profile_words(k.profiles));
      if (!k.in_defaults) facts += ", not in [defaults]";
    }
    out += fmt::format("\\&{}.\n.br\n\\&{}\n", roff(facts), roff(k.doc));
  }
  return out;
}

}  // namespace dnbridge::daemon
