#include "bridge/rack/device_rack.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "bridge/common/bytes.hpp"
#include "bridge/rack/publish_gate.hpp"

namespace dnbridge::rack {

using devicenet::MacId;

namespace {

const profiles::eds::EdsFile& eds_of(const DeviceConfig& d) {
  if (!d.eds) {
    throw std::invalid_argument(
        fmt::format("node {} ({}): no EDS file read", d.node.mac.value(), d.node.name));
  }
  return *d.eds;
}

}  // namespace

devicenet::NodeConfig DeviceRack::scan_entry(const DeviceConfig& d) {
  std::string why;
  (void)eds_of(d);  // throws without a file
  auto profile = profiles::eds::make_node_profile(d.eds, d.settings, &why);
  if (!profile) {
    throw std::invalid_argument(
        fmt::format("node {} ({}): {}: {}", d.node.mac.value(), d.node.name, d.eds_path, why));
  }
  devicenet::NodeConfig node = d.node;
  node.profile = std::move(*profile);
  return node;
}

devicenet::ScannerConfig DeviceRack::scanner_config(devicenet::ScannerConfig port,
                                                    const std::vector<DeviceConfig>& devices) {
  for (const auto& d : devices) port.nodes.push_back(scan_entry(d));
  return port;
}

bool DeviceRack::same_device_settings(const DeviceConfig& a, const DeviceConfig& b) {
  return same_scan_entry(a.node, b.node) && a.eds_digest == b.eds_digest &&
         a.settings == b.settings;
}

DeviceProfile::Slot DeviceProfile::slot_of(const DeviceConfig& d) {
  std::string why;
  auto io = profiles::eds::node_io(eds_of(d), d.settings.connection, &why);
  if (!io) {
    throw std::invalid_argument(
        fmt::format("node {} ({}): {}", d.node.mac.value(), d.node.name, why));
  }
  return {std::make_shared<const profiles::eds::NodeIo>(std::move(*io)), d.eds, d.settings};
}

DeviceView DeviceProfile::view_of(const DeviceConfig& d, const Slot& slot) {
  DeviceView v;
  v.mac = d.node.mac;
  v.name = d.node.name;
  v.reason = "not started";
  v.product = eds_of(d).device.product_name;
  v.io = slot.io;
  v.safe_state_of_device = slot.settings.safe_state_of_device;
  return v;
}

void DeviceProfile::carry_over(const DeviceView&, DeviceView&) {}

void DeviceProfile::on_online(DeviceView& v, const Slot& slot, const devicenet::Node& node) {
  // The safe state's settings follow the parameters' (profiles::eds::make_node_profile):
  // the safe_state parameters, or with safe_state = "device" the ones the
  // EDS names for it, read and kept.
  std::vector<const profiles::eds::Param*> params;
  if (slot.settings.safe_state_of_device) {
    params = profiles::eds::device_safe_state(*slot.eds, slot.settings).read;
  } else {
    for (const auto& given : slot.settings.safe_state)
      params.push_back(slot.eds->param(given.name));
  }
  const auto& in_force = node.settings_in_force();
  const std::size_t first = slot.settings.parameters.size();
  std::string text;
  bool read = false;
  for (std::size_t i = 0; i < params.size(); ++i) {
    const profiles::eds::Param* p = params[i];
    if (p == nullptr || first + i >= in_force.size()) continue;
    read = true;
    const auto& bytes = in_force[first + i];
    const std::uint64_t raw = little_endian(bytes);
    const auto bits = static_cast<std::uint16_t>(std::min<std::size_t>(bytes.size() * 8, 64));
    text += fmt::format("{}Param{} {} = {}{}", text.empty() ? "" : "; ", p->number, p->name,
                        profiles::eds::from_raw(p->type, bits, raw),
                        p->units.empty() ? "" : " " + p->units);
  }
  if (slot.settings.safe_state_of_device) {
    text = text.empty() ? "the device's own (safe_state = \"device\"): its EDS names no "
                          "parameter for it"
                        : "the device's own (safe_state = \"device\"): " + text;
  }
  v.safe_state_text = std::move(text);
  v.safe_state_read = read;
}

bool DeviceProfile::take_inputs(DeviceView& v, const Slot& slot, Bytes data) {
  v.inputs.assign(data.begin(), data.end());
  v.input_values = profiles::eds::decode(slot.io->produced, data);
  return true;
}

void DeviceProfile::take_applied(DeviceView& v, const Slot& slot, Bytes outputs) {
  v.outputs_applied.assign(outputs.begin(), outputs.end());
  v.output_values = profiles::eds::decode(slot.io->consumed, outputs);
}

Status DeviceRack::command(MacId mac, const std::vector<std::uint8_t>& data,
                           std::string_view issuer, TimePoint now) {
  DeviceView* v = find(mac);
  if (!v || !scanner()) return Errc::kOutOfRange;
  const profiles::eds::IoLayout& out = slot(mac).io->consumed;
  if (out.size == 0) {
    return refuse(*v, Errc::kUnsupported,
                  fmt::format("from {}: the node's connection has no outputs", issuer));
  }
  std::string why;
  if (auto s = profiles::eds::check(out, Bytes(data.data(), data.size()), &why); !s) {
    return refuse(*v, s, fmt::format("from {}: {}", issuer, why));
  }
  if (auto s = refuse_unless_online(*v, issuer); !s) return s;
  return apply_command(*v, Bytes(data.data(), data.size()), data, issuer, now);
}

Status DeviceRack::command(MacId mac, const std::vector<profiles::eds::FieldSetting>& fields,
                           std::string_view issuer, TimePoint now) {
  DeviceView* v = find(mac);
  if (!v || !scanner()) return Errc::kOutOfRange;
  const profiles::eds::IoLayout& out = slot(mac).io->consumed;
  if (out.size != 0 && out.fields.empty()) {
    return refuse(*v, Errc::kUnsupported,
                  fmt::format("from {}: the EDS names no fields of the node's outputs (\"{}\"); "
                              "command them as bytes",
                              issuer, out.name));
  }
  std::string why;
  auto data = profiles::eds::encode(out, fields, &why);
  if (!data) return refuse(*v, data.error(), fmt::format("from {}: {}", issuer, why));
  return command(mac, *data, issuer, now);
}

Status DeviceRack::command(MacId mac, const MalformedCommand& command, std::string_view issuer,
                           TimePoint) {
  DeviceView* v = find(mac);
  if (!v) return Errc::kOutOfRange;
  return refuse(*v, Errc::kMalformed, fmt::format("from {}: {}", issuer, command.why));
}

Status DeviceRack::command(MacId mac, const NodeCommand& command, std::string_view issuer,
                           TimePoint now) {
  if (const auto* bytes = command.as<std::vector<std::uint8_t>>()) {
    return this->command(mac, *bytes, issuer, now);
  }
  if (const auto* fields = command.as<std::vector<profiles::eds::FieldSetting>>()) {
    return this->command(mac, *fields, issuer, now);
  }
  if (const auto* malformed = command.as<MalformedCommand>()) {
    return this->command(mac, *malformed, issuer, now);
  }
  return refuse_other_form(mac, issuer);
}

std::unique_ptr<StateGate> DeviceRack::state_gate(const PublishPolicy& policy) const {
  return std::make_unique<DeviceStateGate>(policy);
}

}  // namespace dnbridge::rack
