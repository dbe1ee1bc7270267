#pragma once
// The state of a rack's devices described by their EDS files (profile
// "eds") as the layer above sees it: NodeRack with the connection's data as
// bytes and as the EDS's named, typed fields (profiles/eds/io_layout.hpp).
// Commands come as the output data's bytes or as its fields; either way
// every field is checked against its type and the EDS's limits before the
// master gets the bytes.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bridge/profiles/eds/eds_file.hpp"
#include "bridge/profiles/eds/io_layout.hpp"
#include "bridge/profiles/eds/node_profile.hpp"
#include "bridge/rack/node_rack.hpp"

namespace dnbridge::rack {

class DeviceRack;

struct DeviceConfig {
  using Rack = DeviceRack;
  devicenet::NodeConfig node;  // its profile is made from the EDS (scanner_config)
  NoCommanderPolicy no_commander = NoCommanderPolicy::kIdle;
  ResumePolicy resume = ResumePolicy::kFreshCommand;
  // Zero: off. Otherwise a command must be written again at least this
  // often to stay in force (NodeRack::expire_silent_commanders).
  Duration command_refresh{};
  std::shared_ptr<const profiles::eds::EdsFile> eds;
  std::string eds_path;             // as configured, for people
  std::uint64_t eds_digest = 0;     // of the file's text: a changed file is a changed device
  profiles::eds::EdsNode settings;  // connection, parameters, safe state
};

struct DeviceView : NodeView {
  std::string product;  // the EDS's product name
  // The connection's data as the EDS lays it out (field names, types, units).
  std::shared_ptr<const profiles::eds::NodeIo> io;
  // Inputs from the last poll response (valid once `has_inputs`): the bytes
  // and their numeric fields.
  std::vector<std::uint8_t> inputs;
  std::vector<profiles::eds::FieldValue> input_values;
  // Outputs the device applied with its last answered poll (when not
  // `outputs_idle`).
  std::vector<std::uint8_t> outputs_applied;
  std::vector<profiles::eds::FieldValue> output_values;
  // Outputs requested by the layer above (not yet necessarily applied), by
  // `commanded_by`.
  std::optional<std::vector<std::uint8_t>> outputs_requested;
  std::string idle_reason() const { return idle_text(outputs_requested.has_value()); }

  // The safe state the device had when the node last came online: each
  // safe_state parameter as read back after the download, in words
  // ("Param6 Output fault action = 0; ..."), or with safe_state = "device"
  // the device's own as read; empty until then.
  std::string safe_state_text;
  bool safe_state_read = false;       // a parameter of it was read (the text has values)
  bool safe_state_of_device = false;  // safe_state = "device"
};

struct DeviceProfile {
  static constexpr std::string_view kName = "eds";
  using Config = DeviceConfig;
  using View = DeviceView;
  using Outputs = std::vector<std::uint8_t>;
  struct Slot {
    std::shared_ptr<const profiles::eds::NodeIo> io;
    std::shared_ptr<const profiles::eds::EdsFile> eds;
    profiles::eds::EdsNode settings;
  };
  static Slot slot_of(const DeviceConfig& device);
  static DeviceView view_of(const DeviceConfig& device, const Slot& slot);
  static void carry_over(const DeviceView& old, DeviceView& fresh);
  // What the device's safe state is.
  static void on_online(DeviceView& view, const Slot& slot, const devicenet::Node& node);
  static bool take_inputs(DeviceView& view, const Slot& slot, Bytes data);
  static void take_applied(DeviceView& view, const Slot& slot, Bytes outputs);
};

// A command that cannot be taken as it came (e.g. bytes and fields both):
// refused whole, with `why`.
struct MalformedCommand {
  std::string why;
};

class DeviceRack final : public NodeRack<DeviceProfile> {
 public:
  // The master's scan-list entry, its node profile made from the EDS.
  // Throws std::invalid_argument, naming the node and what is wrong, for one
  // the EDS does not allow.
  static devicenet::NodeConfig scan_entry(const DeviceConfig& device);
  // Adds the devices' nodes to the scan list.
  static devicenet::ScannerConfig scanner_config(devicenet::ScannerConfig port,
                                                 const std::vector<DeviceConfig>& devices);
  // The settings the master brings to the device: its EDS, connection,
  // parameters and safe state, and the scan-list entry but for the name.
  static bool same_device_settings(const DeviceConfig& a, const DeviceConfig& b);

  using NodeRack::NodeRack;

  // New outputs as the output data's bytes: refused unless the node is
  // online, has outputs, the size is theirs and every field of them is
  // within its type and the EDS's limits. kOutOfRange for a MAC not in the
  // rack. A refusal is counted and its reason kept in the view.
  Status command(devicenet::MacId mac, const std::vector<std::uint8_t>& data,
                 std::string_view issuer, TimePoint now);
  // The same, the outputs given field by field (every numeric field once).
  Status command(devicenet::MacId mac, const std::vector<profiles::eds::FieldSetting>& fields,
                 std::string_view issuer, TimePoint now);
  // Refused, counted and its reason kept as any refusal.
  Status command(devicenet::MacId mac, const MalformedCommand& command, std::string_view issuer,
                 TimePoint now);
  // A NodeCommand of any of the three forms above; any other is refused.
  Status command(devicenet::MacId mac, const NodeCommand& command, std::string_view issuer,
                 TimePoint now) override;
  std::unique_ptr<StateGate> state_gate(const PublishPolicy& policy) const override;

  const std::vector<DeviceView>& devices() const { return nodes(); }
  const DeviceView* device(devicenet::MacId mac) const { return node(mac); }
};

}  // namespace dnbridge::rack
