#pragma once
// The rack layer of the test-only profile "dio", a digital I/O block: the
// example I/O block of deploy/eds (8 digital inputs, module status and an
// analog input produced, 8 digital outputs and a pad byte consumed), known
// by its identity and its Parameter object rather than by its EDS file. It
// is what a profile supplies to NodeRack (node_rack.hpp) and PortNodes
// (port_nodes.hpp): its configuration, view, scan-list entry and command
// form; its safe state is the outputs' fault and idle values, downloaded and
// read back.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bridge/rack/node_rack.hpp"
#include "bridge/rack/publish_gate.hpp"

namespace dnbridge::test::dio {

class DioRack;

struct DioConfig {
  using Rack = DioRack;
  devicenet::NodeConfig node;  // its profile is made by DioRack::scan_entry
  rack::NoCommanderPolicy no_commander = rack::NoCommanderPolicy::kIdle;
  rack::ResumePolicy resume = rack::ResumePolicy::kFreshCommand;
  Duration command_refresh{};
  // The safe state: what the outputs take on a fault (the connection timed
  // out) and when polled idle.
  std::uint8_t fault_outputs = 0;
  std::uint8_t idle_outputs = 0;
};

// A command's outputs, one bit per digital output (a type of its own, so
// that no other profile's rack takes it for its own form).
struct DioOutputs {
  std::uint8_t bits = 0;
  friend bool operator==(const DioOutputs&, const DioOutputs&) = default;
};

struct DioView : rack::NodeView {
  std::uint8_t inputs = 0;  // from the last poll response (valid once has_inputs)
  std::uint8_t module_status = 0;
  std::int16_t analog_input_mv = 0;
  std::uint8_t outputs_applied = 0;  // with the last answered poll (when not outputs_idle)
  std::optional<DioOutputs> outputs_requested;
  std::string idle_reason() const { return idle_text(outputs_requested.has_value()); }
  // The safe state as read back when the node last came online.
  std::optional<std::uint8_t> fault_outputs_read, idle_outputs_read;
};

struct DioProfile {
  static constexpr std::string_view kName = "dio";
  using Config = DioConfig;
  using View = DioView;
  using Outputs = DioOutputs;
  struct Slot {};
  static Slot slot_of(const DioConfig&) { return {}; }
  static DioView view_of(const DioConfig& c, const Slot&);
  static void carry_over(const DioView&, DioView&) {}
  static void on_online(DioView& view, const Slot&, const devicenet::Node& node);
  static bool take_inputs(DioView& view, const Slot&, Bytes data);
  static void take_applied(DioView& view, const Slot&, Bytes outputs);
};

class DioRack final : public rack::NodeRack<DioProfile> {
 public:
  static devicenet::NodeConfig scan_entry(const DioConfig& c);
  static bool same_device_settings(const DioConfig& a, const DioConfig& b);

  using NodeRack::NodeRack;

  // New outputs, refused unless the node is online.
  Status command(devicenet::MacId mac, DioOutputs outputs, std::string_view issuer, TimePoint now);
  Status command(devicenet::MacId mac, const rack::NodeCommand& command, std::string_view issuer,
                 TimePoint now) override;
  std::unique_ptr<rack::StateGate> state_gate(const rack::PublishPolicy& policy) const override;
};

}  // namespace dnbridge::test::dio
