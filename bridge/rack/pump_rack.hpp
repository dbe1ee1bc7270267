#pragma once
// The state of a rack's pumps (CDN127s) as the layer above sees it: the
// master's events turned into plain values with meaning (decoded inputs,
// applied outputs, life cycle, identity, errors), by NodeRack with the
// CDN127's data. The DDS face publishes from here; the demo draws it.
// Commands are checked here before they reach the master.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"
#include "bridge/profiles/cdn127/node_profile.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"
#include "bridge/rack/node_rack.hpp"

namespace dnbridge::rack {

class PumpRack;

// One pump's configuration in the rack: the scan-list entry and the CDN127
// I/O configuration its poll data is decoded with.
struct PumpConfig {
  using Rack = PumpRack;
  devicenet::NodeConfig node;
  NoCommanderPolicy no_commander = NoCommanderPolicy::kIdle;
  ResumePolicy resume = ResumePolicy::kFreshCommand;
  // Zero: off. Otherwise a command must be written again at least this
  // often to stay in force (NodeRack::expire_silent_commanders).
  Duration command_refresh{};
  profiles::cdn127::SafeStateConfig safe_state;
  profiles::cdn127::IoConfiguration io;
  // The identity the device must show; the CDN127's (vendor 59, product type
  // 27, product code 1888) when not given.
  std::optional<devicenet::ExpectedIdentity> identity;
};

struct PumpView : NodeView {
  // Inputs from the last poll response (valid once `has_inputs`).
  profiles::cdn127::PollInputs inputs;
  // Outputs the device applied with its last answered poll (when not
  // `outputs_idle`).
  profiles::cdn127::PumpOutputs outputs_applied;
  // Outputs requested by the layer above (not yet necessarily applied), by
  // `commanded_by`.
  std::optional<profiles::cdn127::PumpOutputs> outputs_requested;
  // "idle: ..." when no command is in force; empty otherwise.
  std::string idle_reason() const { return idle_text(outputs_requested.has_value()); }

  // The outputs' fault and idle actions the device had when the node last
  // came online (read back after the download, or the device's own kept),
  // and where they came from.
  std::optional<profiles::cdn127::SafeState> safe_state;
  profiles::cdn127::SafeStateSource safe_state_source =
      profiles::cdn127::SafeStateSource::kConfiguration;
  std::string safe_state_text;  // in words, for the outputs the configuration has

  // Poll responses that carried an input out of range (its other inputs were
  // taken; PollInputs::analog_input_in_range says which channel).
  std::uint64_t responses_with_invalid_inputs = 0;
};

// The CDN127 as a NodeRack profile: its poll data decoded with the I/O
// configuration's format.
struct PumpProfile {
  static constexpr std::string_view kName = "cdn127";
  using Config = PumpConfig;
  using View = PumpView;
  using Outputs = profiles::cdn127::PumpOutputs;
  struct Slot {
    profiles::cdn127::IoConfiguration io;
    profiles::cdn127::PollFormat format;
  };
  static Slot slot_of(const PumpConfig& pump);
  static PumpView view_of(const PumpConfig& pump, const Slot& slot);
  static void carry_over(const PumpView& old, PumpView& fresh);
  // What the device's safe state is.
  static void on_online(PumpView& view, const Slot& slot, const devicenet::Node& node);
  static bool take_inputs(PumpView& view, const Slot& slot, Bytes data);
  static void take_applied(PumpView& view, const Slot& slot, Bytes outputs);
};

class PumpRack final : public NodeRack<PumpProfile> {
 public:
  // The master's scan-list entry, its node profile made from the pump's I/O
  // configuration. Throws std::invalid_argument for an invalid one.
  static devicenet::NodeConfig scan_entry(const PumpConfig& pump);
  // The port's scan list of `pumps` alone (the nodes `port` had replaced).
  static devicenet::ScannerConfig scanner_config(devicenet::ScannerConfig port,
                                                 const std::vector<PumpConfig>& pumps);
  // The settings the master brings to the device (all but the name and the
  // bridge's own handling).
  static bool same_device_settings(const PumpConfig& a, const PumpConfig& b);

  using NodeRack::NodeRack;

  // Validates and forwards new outputs: refused, never clipped, when out of
  // range; refused when the configuration has no room for them (e.g. an
  // analog value for a configuration without analog output); refused while
  // the node is not online (after a loss, only a command taken after its
  // return counts). A refusal is counted and its
  // reason kept in the pump's view; nothing of the command is applied.
  // kOutOfRange for a MAC not in the rack.
  Status command(devicenet::MacId mac, const profiles::cdn127::PumpOutputs& outputs,
                 std::string_view issuer, TimePoint now);
  Status command(devicenet::MacId mac, const profiles::cdn127::PumpOutputs& outputs,
                 TimePoint now) {
    return command(mac, outputs, "local", now);
  }
  // A NodeCommand of PumpOutputs; any other form is refused.
  Status command(devicenet::MacId mac, const NodeCommand& command, std::string_view issuer,
                 TimePoint now) override;
  std::unique_ptr<StateGate> state_gate(const PublishPolicy& policy) const override;

  const std::vector<PumpView>& pumps() const { return nodes(); }
  const PumpView* pump(devicenet::MacId mac) const { return node(mac); }
};

}  // namespace dnbridge::rack
