#include "bridge/rack/pump_rack.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "bridge/profiles/cdn127/node_profile.hpp"

namespace dnbridge::rack {

using devicenet::MacId;
using devicenet::NodeState;
namespace cdn127 = profiles::cdn127;

devicenet::ScannerConfig PumpRack::scanner_config(devicenet::ScannerConfig port,
                                                  const std::vector<PumpConfig>& pumps) {
  port.nodes.clear();
  for (const auto& p : pumps) {
    auto profile = cdn127::make_node_profile(p.io, p.safe_state);
    if (!profile) {
      throw std::invalid_argument(fmt::format("node {} ({}): invalid I/O configuration: {}",
                                              p.node.mac.value(), p.node.name,
                                              profile.error().message()));
    }
    devicenet::NodeConfig node = p.node;
    node.profile = std::move(*profile);
    if (p.identity) node.profile.identity = *p.identity;
    port.nodes.push_back(std::move(node));
  }
  return port;
}

PumpRack::Slot PumpRack::slot_of(const PumpConfig& p) {
  auto format = cdn127::poll_format(p.io);
  if (!format) {
    throw std::invalid_argument(
        fmt::format("node {}: invalid I/O configuration", p.node.mac.value()));
  }
  return {p.io, *format, p.no_commander, p.resume};
}

PumpView PumpRack::view_of(const PumpConfig& p) {
  PumpView v;
  v.mac = p.node.mac;
  v.name = p.node.name;
  v.reason = "not started";
  v.safe_state_source = p.safe_state.source;
  return v;
}

PumpRack::PumpRack(const std::vector<PumpConfig>& pumps) {
  index_.fill(-1);
  for (const auto& p : pumps) add(p);
}

void PumpRack::add(const PumpConfig& p) {
  if (index_[p.node.mac.value()] >= 0) {
    throw std::invalid_argument(fmt::format("node {} is in the rack twice", p.node.mac.value()));
  }
  slots_.push_back(slot_of(p));
  index_[p.node.mac.value()] = static_cast<int>(views_.size());
  views_.push_back(view_of(p));
}

void PumpRack::remove(MacId mac) {
  const int i = index_[mac.value()];
  if (i < 0) return;
  views_.erase(views_.begin() + i);
  slots_.erase(slots_.begin() + i);
  index_.fill(-1);
  for (std::size_t k = 0; k < views_.size(); ++k) {
    index_[views_[k].mac.value()] = static_cast<int>(k);
  }
}

void PumpRack::replace(const PumpConfig& p) {
  const int i = index_[p.node.mac.value()];
  if (i < 0) return add(p);
  const auto index = static_cast<std::size_t>(i);
  slots_[index] = slot_of(p);
  PumpView& v = views_[index];
  // Its counters go on (they are the pump's, whatever its settings); the
  // rest starts again.
  PumpView fresh = view_of(p);
  fresh.commands_accepted = v.commands_accepted;
  fresh.commands_refused = v.commands_refused;
  fresh.responses_with_invalid_inputs = v.responses_with_invalid_inputs;
  fresh.reason = "configuration changed: released, to be configured again";
  fresh.state_since = v.state_since;
  fresh.idle_cause = IdleCause::kReconfigured;
  fresh.changes = v.changes + 1;
  fresh.status_changes = v.status_changes + 1;
  v = std::move(fresh);
}

void PumpRack::update(const PumpConfig& p, TimePoint now) {
  PumpView* v = find(p.node.mac);
  if (!v) return;
  Slot& slot = slots_[static_cast<std::size_t>(index_[p.node.mac.value()])];
  slot.no_commander = p.no_commander;
  slot.resume = p.resume;
  v->name = p.node.name;
  ++v->changes;
  ++v->status_changes;
  // Held for a commander that has gone: the new policy applies now.
  if (slot.held_without_commander && p.no_commander == NoCommanderPolicy::kIdle) {
    (void)release_command(p.node.mac, now);
  }
}

PumpView* PumpRack::find(MacId mac) {
  const int i = index_[mac.value()];
  return i < 0 ? nullptr : &views_[static_cast<std::size_t>(i)];
}

const PumpView* PumpRack::pump(MacId mac) const {
  const int i = index_[mac.value()];
  return i < 0 ? nullptr : &views_[static_cast<std::size_t>(i)];
}

std::string_view to_string(IdleCause cause) noexcept {
  switch (cause) {
    case IdleCause::kNoCommandYet:
      return "idle: no command yet";
    case IdleCause::kNoCommander:
      return "idle: no live commander";
    case IdleCause::kAfterLoss:
      return "idle: waiting for a new command after reconnection";
    case IdleCause::kReconfigured:
      return "idle: configured again after a reload, waiting for a new command";
  }
  return "idle";
}

Status PumpRack::refuse(PumpView& view, Status why, std::string text) {
  ++view.commands_refused;
  view.last_command_refused = std::move(text);
  ++view.changes;
  ++view.status_changes;
  return why;
}

Status PumpRack::command(MacId mac, const cdn127::PumpOutputs& outputs, std::string_view issuer,
                         TimePoint now) {
  PumpView* v = find(mac);
  if (!v || !scanner_) return Errc::kOutOfRange;
  if (auto ok = cdn127::validate(outputs); !ok) {
    return refuse(*v, ok,
                  fmt::format("from {}: analog output {} is out of range 0..{}", issuer,
                              outputs.analog_out_raw, cdn127::kAnalogMaxRaw));
  }
  const auto& slot = slots_[static_cast<std::size_t>(index_[mac.value()])];
  // Only an online node is commanded: a command kept for a node that is
  // away would start its pump whenever it comes (back), perhaps hours later.
  if (!v->online) {
    return refuse(*v, Errc::kNotConnected,
                  v->idle_cause == IdleCause::kAfterLoss
                      ? fmt::format("from {}: the node was lost and is not back online; only a "
                                    "command written after its return is applied",
                                    issuer)
                      : fmt::format("from {}: the node is not online ({}); a command applies "
                                    "only to an online node",
                                    issuer, devicenet::to_string(v->state)));
  }
  const auto& layout = slot.format.request;
  // An output the configuration leaves out of the poll request cannot be
  // commanded: refuse it rather than drop it silently.
  if (outputs.analog_out_raw != 0 && layout.aout_count == 0) {
    return refuse(*v, Errc::kUnsupported,
                  fmt::format("from {}: the node's configuration has no analog output", issuer));
  }
  if (outputs.pump_on && slot.io.num_digital_outputs < 1) {
    return refuse(*v, Errc::kUnsupported,
                  fmt::format("from {}: the node's configuration has no pump output", issuer));
  }
  if (outputs.n2_ballast_on && slot.io.num_digital_outputs < 3) {
    return refuse(
        *v, Errc::kUnsupported,
        fmt::format("from {}: the node's configuration has no N2 ballast output", issuer));
  }
  std::array<std::uint8_t, 8> buf{};
  auto size = cdn127::encode_poll_request(layout, outputs, MutableBytes(buf));
  if (!size)
    return refuse(*v, size.error(), fmt::format("from {}: {}", issuer, size.error().message()));
  if (auto s = scanner_->set_outputs(mac, Bytes(buf.data(), *size), now); !s) {
    return refuse(*v, s, fmt::format("from {}: {}", issuer, s.error().message()));
  }
  v->outputs_requested = outputs;
  v->commanded_by = std::string(issuer);
  slots_[static_cast<std::size_t>(index_[mac.value()])].held_without_commander = false;
  ++v->commands_accepted;
  ++v->changes;
  return {};
}

Status PumpRack::release_command(MacId mac, TimePoint now) {
  PumpView* v = find(mac);
  if (!v || !scanner_) return Errc::kOutOfRange;
  auto& slot = slots_[static_cast<std::size_t>(index_[mac.value()])];
  if (slot.no_commander == NoCommanderPolicy::kHoldLastOutputs) {
    slot.held_without_commander = v->outputs_requested.has_value();
    return {};
  }
  slot.held_without_commander = false;
  if (v->outputs_requested) v->idle_cause = IdleCause::kNoCommander;
  v->outputs_requested.reset();
  v->commanded_by.clear();
  ++v->changes;
  return scanner_->set_idle(mac, true, now);
}

void PumpRack::on_loss(PumpView& v, const Slot& slot, NodeState to, TimePoint at) {
  // A device fault voids the command whatever the policy: the fault (a loss
  // of the outputs' supply) may clear long after.
  if (slot.resume == ResumePolicy::kLastCommand && to != NodeState::kDeviceFault) return;
  // The last command was for the device as it was before: after a power
  // cycle, a cable or a bus-off nobody has seen its state since. Idle polls
  // until a commander, having seen it back, commands it again.
  v.idle_cause = IdleCause::kAfterLoss;
  v.outputs_requested.reset();
  v.commanded_by.clear();
  if (scanner_) (void)scanner_->set_idle(v.mac, true, at);
}

void PumpRack::on_online(PumpView& v) {
  const devicenet::Node* node = scanner_ ? scanner_->node(v.mac) : nullptr;
  if (!node) return;
  const auto& settings = node->config().profile.settings;
  v.safe_state = cdn127::safe_state_in_force(settings, node->settings_in_force());
  const Slot& slot = slots_[static_cast<std::size_t>(index_[v.mac.value()])];
  v.safe_state_text = v.safe_state ? cdn127::describe(*v.safe_state, slot.io) : "not known";
}

void PumpRack::on_port_state(devicenet::PortState state, const std::string& reason, TimePoint) {
  port_state_ = state;
  port_reason_ = reason;
}

void PumpRack::on_node_state(MacId mac, NodeState from, NodeState to, const std::string& reason,
                             TimePoint at) {
  PumpView* v = find(mac);
  if (!v) return;
  const Slot& slot = slots_[static_cast<std::size_t>(index_[mac.value()])];
  // A device fault voids a command even before the node was first online:
  // the fault may clear long after the command was given.
  if ((from == NodeState::kOnline && to != NodeState::kOnline && to != NodeState::kStopped) ||
      to == NodeState::kDeviceFault) {
    on_loss(*v, slot, to, at);
  }
  if (to == NodeState::kOnline) on_online(*v);
  v->state = to;
  v->reason = reason;
  v->state_since = at;
  v->online = to == NodeState::kOnline;
  v->has_inputs = false;  // until a poll response since this transition
  v->inputs_withheld_when_idle = false;
  ++v->changes;
  ++v->status_changes;
}

void PumpRack::on_node_identity(MacId mac, const devicenet::NodeIdentity& identity, TimePoint) {
  if (PumpView* v = find(mac)) {
    v->identity = identity;
    const devicenet::Node* node = scanner_ ? scanner_->node(mac) : nullptr;
    v->minor_faults = node ? node->minor_faults() : "";
    ++v->changes;
    ++v->status_changes;
  }
}

void PumpRack::refresh_applied(std::size_t index) {
  PumpView& v = views_[index];
  const devicenet::Node* node = scanner_ ? scanner_->node(v.mac) : nullptr;
  if (!node) return;
  v.outputs_idle = node->applied_idle();
  if (!v.outputs_idle) {
    if (auto out =
            cdn127::decode_poll_request(slots_[index].format.request, node->applied_outputs());
        out) {
      v.outputs_applied = *out;
    }
  }
}

void PumpRack::on_poll_response(MacId mac, Bytes data, TimePoint rx_time) {
  const int i = index_[mac.value()];
  if (i < 0) return;
  const auto index = static_cast<std::size_t>(i);
  PumpView& v = views_[index];
  const Slot& slot = slots_[index];
  if (data.empty()) {
    // An idle poll answered with no data: the device applied its idle
    // outputs, and said nothing of its inputs. What they last were is not
    // what they are: no inputs are published until a response carries them.
    if (v.has_inputs || !v.inputs_withheld_when_idle) ++v.status_changes;
    v.has_inputs = false;
    v.inputs_withheld_when_idle = true;
    refresh_applied(index);
    ++v.changes;
    return;
  }
  if (v.inputs_withheld_when_idle) ++v.status_changes;
  v.inputs_withheld_when_idle = false;
  auto inputs = cdn127::decode_poll_response(slot.format.response, slot.io.no_nc_mask, data);
  if (!inputs) return;  // the master checked the size
  // A channel out of range is published as invalid; NodeStatus says which,
  // so it changes when the set of invalid channels does.
  if (!inputs->all_in_range()) ++v.responses_with_invalid_inputs;
  if (inputs->analog_input_in_range != v.inputs.analog_input_in_range) ++v.status_changes;
  v.inputs = *inputs;
  v.has_inputs = true;
  v.inputs_time = rx_time;
  refresh_applied(index);
  ++v.changes;
}

void PumpRack::on_device_state(MacId mac, std::uint8_t state, TimePoint) {
  if (PumpView* v = find(mac)) {
    v->device_state = state;
    ++v->changes;
    ++v->status_changes;
  }
}

}  // namespace dnbridge::rack
