#include "bridge/rack/pump_rack.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "bridge/profiles/cdn127/node_profile.hpp"
#include "bridge/rack/publish_gate.hpp"

namespace dnbridge::rack {

using devicenet::MacId;
namespace cdn127 = profiles::cdn127;

devicenet::NodeConfig PumpRack::scan_entry(const PumpConfig& p) {
  auto profile = cdn127::make_node_profile(p.io, p.safe_state);
  if (!profile) {
    throw std::invalid_argument(fmt::format("node {} ({}): invalid I/O configuration: {}",
                                            p.node.mac.value(), p.node.name,
                                            profile.error().message()));
  }
  devicenet::NodeConfig node = p.node;
  node.profile = std::move(*profile);
  if (p.identity) node.profile.identity = *p.identity;
  return node;
}

devicenet::ScannerConfig PumpRack::scanner_config(devicenet::ScannerConfig port,
                                                  const std::vector<PumpConfig>& pumps) {
  port.nodes.clear();
  for (const auto& p : pumps) port.nodes.push_back(scan_entry(p));
  return port;
}

bool PumpRack::same_device_settings(const PumpConfig& a, const PumpConfig& b) {
  return same_scan_entry(a.node, b.node) && a.io == b.io && a.safe_state == b.safe_state &&
         a.identity == b.identity;
}

PumpProfile::Slot PumpProfile::slot_of(const PumpConfig& p) {
  auto format = cdn127::poll_format(p.io);
  if (!format) {
    throw std::invalid_argument(
        fmt::format("node {}: invalid I/O configuration", p.node.mac.value()));
  }
  return {p.io, *format};
}

PumpView PumpProfile::view_of(const PumpConfig& p, const Slot&) {
  PumpView v;
  v.mac = p.node.mac;
  v.name = p.node.name;
  v.reason = "not started";
  v.safe_state_source = p.safe_state.source;
  return v;
}

void PumpProfile::carry_over(const PumpView& old, PumpView& fresh) {
  fresh.responses_with_invalid_inputs = old.responses_with_invalid_inputs;
}

void PumpProfile::on_online(PumpView& v, const Slot& slot, const devicenet::Node& node) {
  const auto& settings = node.config().profile.settings;
  v.safe_state = cdn127::safe_state_in_force(settings, node.settings_in_force());
  v.safe_state_text = v.safe_state ? cdn127::describe(*v.safe_state, slot.io) : "not known";
}

bool PumpProfile::take_inputs(PumpView& v, const Slot& slot, Bytes data) {
  auto inputs = cdn127::decode_poll_response(slot.format.response, slot.io.no_nc_mask, data);
  if (!inputs) return false;
  // A channel out of range is published as invalid; NodeStatus says which,
  // so it changes when the set of invalid channels does.
  if (!inputs->all_in_range()) ++v.responses_with_invalid_inputs;
  if (inputs->analog_input_in_range != v.inputs.analog_input_in_range) ++v.status_changes;
  v.inputs = *inputs;
  return true;
}

void PumpProfile::take_applied(PumpView& v, const Slot& slot, Bytes outputs) {
  if (auto out = cdn127::decode_poll_request(slot.format.request, outputs); out) {
    v.outputs_applied = *out;
  }
}

Status PumpRack::command(MacId mac, const cdn127::PumpOutputs& outputs, std::string_view issuer,
                         TimePoint now) {
  PumpView* v = find(mac);
  if (!v || !scanner()) return Errc::kOutOfRange;
  if (auto ok = cdn127::validate(outputs); !ok) {
    return refuse(*v, ok,
                  fmt::format("from {}: analog output {} is out of range 0..{}", issuer,
                              outputs.analog_out_raw, cdn127::kAnalogMaxRaw));
  }
  if (auto s = refuse_unless_online(*v, issuer); !s) return s;
  const Slot& s = slot(mac);
  const auto& layout = s.format.request;
  // An output the configuration leaves out of the poll request cannot be
  // commanded: refuse it rather than drop it silently.
  if (outputs.analog_out_raw != 0 && layout.aout_count == 0) {
    return refuse(*v, Errc::kUnsupported,
                  fmt::format("from {}: the node's configuration has no analog output", issuer));
  }
  if (outputs.pump_on && s.io.num_digital_outputs < 1) {
    return refuse(*v, Errc::kUnsupported,
                  fmt::format("from {}: the node's configuration has no pump output", issuer));
  }
  if (outputs.n2_ballast_on && s.io.num_digital_outputs < 3) {
    return refuse(
        *v, Errc::kUnsupported,
        fmt::format("from {}: the node's configuration has no N2 ballast output", issuer));
  }
  std::array<std::uint8_t, 8> buf{};
  auto size = cdn127::encode_poll_request(layout, outputs, MutableBytes(buf));
  if (!size) {
    return refuse(*v, size.error(), fmt::format("from {}: {}", issuer, size.error().message()));
  }
  return apply_command(*v, Bytes(buf.data(), *size), outputs, issuer, now);
}

Status PumpRack::command(MacId mac, const NodeCommand& command, std::string_view issuer,
                         TimePoint now) {
  if (const auto* outputs = command.as<cdn127::PumpOutputs>()) {
    return this->command(mac, *outputs, issuer, now);
  }
  return refuse_other_form(mac, issuer);
}

std::unique_ptr<StateGate> PumpRack::state_gate(const PublishPolicy& policy) const {
  return std::make_unique<PumpStateGate>(policy);
}

}  // namespace dnbridge::rack
