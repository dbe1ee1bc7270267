#pragma once
// What the master is told to scan: per port, the master's own MAC and the
// nodes it owns, each with what it must be and how it is configured.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/explicit_client.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::devicenet {

// The identity a scan-list entry expects (Identity object attributes 1..3).
struct ExpectedIdentity {
  std::uint16_t vendor_id = 0;
  std::uint16_t product_type = 0;
  std::uint16_t product_code = 0;

  friend bool operator==(const ExpectedIdentity&, const ExpectedIdentity&) = default;
};

// One attribute the master makes equal to a value before it starts the poll
// connection: read first, written only when it differs, read back. Or, with
// `keep_device_value`, only read: the device's own value is kept (and
// reported, Node::settings_in_force) when it has the size of `value` and, as
// an unsigned little-endian integer, is at most `device_value_max`; another
// is a configuration fault.
struct AttributeSetting {
  std::uint16_t class_id = 0;
  std::uint16_t instance_id = 0;
  std::uint8_t attribute = 0;
  std::vector<std::uint8_t> value;
  std::string name;  // for reasons and logs, e.g. "Configuration.NumAnalogInput"
  bool keep_device_value = false;
  std::uint32_t device_value_max = 0;

  friend bool operator==(const AttributeSetting&, const AttributeSetting&) = default;
};

// What a profile expects an attribute to report, where the device offers
// it: the differences, one sentence each (none when it agrees). `key()`
// tells two expectations apart (configurations are compared by it).
class AttributeVerifier {
 public:
  virtual ~AttributeVerifier() = default;
  virtual std::vector<std::string> differences(Bytes reported) const = 0;
  virtual std::string key() const = 0;
};

// An attribute the master reads after the settings and before the I/O
// connection starts, and that must report what the profile expects (e.g. an
// I/O assembly's member list against the EDS). A difference is a
// configuration fault naming it; a device that refuses the Get (it need not
// offer the attribute) is not compared, and that is logged.
struct AttributeCheck {
  std::uint16_t class_id = 0;
  std::uint16_t instance_id = 0;
  std::uint8_t attribute = 0;
  std::string name;  // "Assembly 100 member list"
  std::shared_ptr<const AttributeVerifier> verifier;

  friend bool operator==(const AttributeCheck& a, const AttributeCheck& b) {
    return a.class_id == b.class_id && a.instance_id == b.instance_id &&
           a.attribute == b.attribute && a.name == b.name &&
           (a.verifier && b.verifier ? a.verifier->key() == b.verifier->key()
                                     : a.verifier == b.verifier);
  }
};

// Where the device reports the poll connection's sizes: Connection instance 2
// attributes 7/8, with a profile-specific fallback (the CDN127's Configuration
// object attributes 16/17) for devices that refuse those.
struct SizeSource {
  std::uint16_t class_id = 0;
  std::uint16_t instance_id = 0;
  std::uint8_t produced_attribute = 0;
  std::uint8_t consumed_attribute = 0;
  bool one_byte = false;    // USINT rather than UINT
  std::string object_name;  // for reasons: "Configuration"

  friend bool operator==(const SizeSource&, const SizeSource&) = default;
};

// The connection beside the poll connection on which the device produces
// its inputs:
// - change of state or cyclic (Connection instance 4): on a change (no
//   sooner than the inhibit time after the last) and at least once per EPR
//   as a heartbeat, or every EPR (cyclic); the master acknowledges each
//   message unless acknowledgment is suppressed;
// - bit-strobe (Connection instance 3): the device answers each of the
//   master's bit-strobe commands (Group 2 message 0, one per port, 64 bits,
//   one per MAC) on Group 1 message 14, in one frame. The master strobes at
//   the shortest poll period of its strobed nodes, and sends every node's
//   bit as 0: a device that takes its bit as an output is not supported.
//   Its EPR is the node's (NodeConfig::expected_packet_rate).
// The outputs, and the device's answer to them, stay on the poll connection
// (which keeps the connections alive at the node's poll period). Nothing for
// 4 x EPR is the node's loss.
enum class InputKind : std::uint8_t { kChangeOfState, kCyclic, kBitStrobe };
std::string_view to_string(InputKind kind) noexcept;  // "change-of-state", "cyclic", "bit-strobe"

struct InputConnection {
  InputKind kind = InputKind::kChangeOfState;
  // Change of state and cyclic: false allocates with 0x40, nothing
  // acknowledged or retried. A bit-strobe response is never acknowledged.
  bool acknowledged = true;
  // Change of state and cyclic: the heartbeat or cycle, as asked.
  Duration expected_packet_rate = milliseconds(1000);
  // Production inhibit time (attribute 17, change of state only); none: the
  // device's own is left.
  std::optional<Duration> inhibit;
  std::vector<std::uint8_t> produced_path;  // attribute 14; empty: the device's default
  std::size_t produced_size = 0;            // message bytes expected

  bool strobed() const noexcept { return kind == InputKind::kBitStrobe; }
  friend bool operator==(const InputConnection&, const InputConnection&) = default;
};

// A bit-strobe response is one frame.
inline constexpr std::size_t kMaxStrobeResponse = 8;

// Device-specific knowledge the node life cycle needs, as data: built by a
// profile (profiles/cdn127/node_profile.hpp).
struct NodeProfile {
  ExpectedIdentity identity;
  std::vector<AttributeSetting> settings;   // applied in order
  std::vector<AttributeCheck> checks;       // then these read and compared
  std::vector<std::uint8_t> produced_path;  // Connection 2 attribute 14 (EPATH)
  std::vector<std::uint8_t> consumed_path;  // Connection 2 attribute 16 (EPATH)
  std::size_t produced_size = 0;            // poll response bytes expected
  std::size_t consumed_size = 0;            // poll request bytes expected
  std::string format_description;           // e.g. "request 4 B [DOUT PAD AOUT] ..."
  bool has_size_fallback = false;
  SizeSource size_fallback;
  std::optional<InputConnection>
      input_connection;  // inputs also on change of state, cyclic or bit-strobe

  friend bool operator==(const NodeProfile&, const NodeProfile&) = default;
};

struct NodeConfig {
  MacId mac;
  std::string name;
  NodeProfile profile;
  Duration poll_period = milliseconds(100);
  // Expected packet rate of the poll connection; the device (and the master)
  // declare the connection dead after 4 x EPR of silence. The device may
  // round it; the value it returns is used.
  Duration expected_packet_rate = milliseconds(1000);
  // Expected packet rate asked for the explicit connection; the master sends
  // a keep-alive request once per returned EPR.
  Duration explicit_packet_rate = milliseconds(2500);
  // Poll at once when new outputs are set, rather than on the next period.
  bool immediate_poll_on_change = true;
  // Polls sent early because the outputs changed are at least this far apart.
  // A change within it after such a poll goes out with one poll when it has
  // elapsed (or with the node's slot, if that comes first), carrying the
  // outputs as they are then; a change that comes alone goes out at once.
  // Zero polls every change at once. The idle poll of an orderly shutdown is
  // not held back by it.
  // 10 ms: a flood of changing commands costs a node ~110 polls/s, ~4 % of a 500 kbit/s bus.
  Duration immediate_poll_min_gap = milliseconds(10);
  // The serial number the device must have (Identity.SerialNumber): another
  // one (a swapped module, a misset MAC switch) is a wrong device. Without
  // it the first serial seen is recorded and a change is warned of.
  std::optional<std::uint32_t> serial_number;
  // This node's own timeouts, for slow devices; the port's otherwise.
  std::optional<Duration> explicit_response_timeout;
  std::optional<Duration> poll_response_timeout;

  friend bool operator==(const NodeConfig&, const NodeConfig&) = default;
};

struct ScannerConfig {
  MacId master_mac;
  // Duplicate MAC ID check of the master's own MAC.
  Duration duplicate_mac_window = seconds(1);
  std::uint16_t vendor_id = 0;
  std::uint32_t serial_number = 0;
  // Explicit messaging.
  ExplicitClient::Config explicit_messaging{};
  // Retry of absent nodes: first after `allocate_retry_min`, doubling up to
  // `allocate_retry_max`, forever. Faulted nodes (wrong device, configuration
  // fault, owned by another master) are re-checked every `fault_recheck`.
  Duration allocate_retry_min = milliseconds(250);
  Duration allocate_retry_max = seconds(5);
  Duration fault_recheck = seconds(10);
  // Consecutive bad poll responses after which the node is reconnected.
  unsigned max_consecutive_errors = 10;
  // Outstanding poll given up after this long (or at the next poll, if sooner).
  Duration poll_response_timeout = milliseconds(50);
  // Polls due within this window of one that is sent now go out with it,
  // ahead of their slot (by at most a quarter of a node's poll period): one
  // wake-up of the master serves several nodes, and no node is polled later
  // than its slot. Zero polls every node exactly at its slot. A batch is
  // about nodes x window / poll period frames at once: the CAN interface's
  // transmit queue should hold that many.
  Duration poll_batch_window = milliseconds(2);
  // A bus scan's wait for each answer of a node it asks (bus_probe.hpp).
  Duration scan_response_timeout = milliseconds(1000);
  std::vector<NodeConfig> nodes;
};

}  // namespace dnbridge::devicenet
