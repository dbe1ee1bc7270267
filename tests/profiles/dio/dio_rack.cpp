#include "profiles/dio/dio_rack.hpp"

#include <fmt/format.h>

#include <array>
#include <tuple>

namespace dnbridge::test::dio {

using devicenet::MacId;

namespace {

// The example I/O block's Parameter object (class 0x0F), attribute 1 of
// instances 6 to 9: the outputs' fault action (0: take the fault value),
// fault value, idle action and idle value.
constexpr std::uint16_t kParameterClass = 0x0F;
constexpr std::uint8_t kParameterValue = 1;
constexpr std::size_t kFaultValue = 1;  // index in the settings, after the fault action
constexpr std::size_t kIdleValue = 3;

devicenet::AttributeSetting parameter(std::uint16_t instance, std::uint8_t value,
                                      std::string_view name) {
  devicenet::AttributeSetting s;
  s.class_id = kParameterClass;
  s.instance_id = instance;
  s.attribute = kParameterValue;
  s.value = {value};
  s.name = fmt::format("Parameter {} ({})", instance, name);
  return s;
}

}  // namespace

devicenet::NodeConfig DioRack::scan_entry(const DioConfig& c) {
  devicenet::NodeConfig node = c.node;
  devicenet::NodeProfile& p = node.profile;
  p.identity = {65001, 7, 1};  // vendor, General Purpose Discrete I/O, product code
  p.settings = {
      parameter(6, 0, "Output fault action"), parameter(7, c.fault_outputs, "Output fault value"),
      parameter(8, 0, "Output idle action"), parameter(9, c.idle_outputs, "Output idle value")};
  p.produced_path = {0x20, 0x04, 0x24, 0x64, 0x30, 0x03};  // Assembly 100, data
  p.consumed_path = {0x20, 0x04, 0x24, 0x96, 0x30, 0x03};  // Assembly 150, data
  p.produced_size = 4;
  p.consumed_size = 2;
  p.format_description = "response 4 B [DI STATUS AI(2)], request 2 B [DO PAD]";
  return node;
}

bool DioRack::same_device_settings(const DioConfig& a, const DioConfig& b) {
  return same_scan_entry(a.node, b.node) &&
         std::tie(a.fault_outputs, a.idle_outputs) == std::tie(b.fault_outputs, b.idle_outputs);
}

DioView DioProfile::view_of(const DioConfig& c, const Slot&) {
  DioView v;
  v.mac = c.node.mac;
  v.name = c.node.name;
  v.reason = "not started";
  return v;
}

void DioProfile::on_online(DioView& v, const Slot&, const devicenet::Node& node) {
  const auto& in_force = node.settings_in_force();
  const auto read = [&](std::size_t i) -> std::optional<std::uint8_t> {
    if (i >= in_force.size() || in_force[i].size() != 1) return std::nullopt;
    return in_force[i][0];
  };
  v.fault_outputs_read = read(kFaultValue);
  v.idle_outputs_read = read(kIdleValue);
}

bool DioProfile::take_inputs(DioView& v, const Slot&, Bytes data) {
  if (data.size() != 4) return false;
  v.inputs = data[0];
  v.module_status = data[1];
  v.analog_input_mv = static_cast<std::int16_t>(little_endian(data.subspan(2, 2)));
  return true;
}

void DioProfile::take_applied(DioView& v, const Slot&, Bytes outputs) {
  if (!outputs.empty()) v.outputs_applied = outputs[0];
}

Status DioRack::command(MacId mac, DioOutputs outputs, std::string_view issuer, TimePoint now) {
  DioView* v = find(mac);
  if (!v || !scanner()) return Errc::kOutOfRange;
  if (auto s = refuse_unless_online(*v, issuer); !s) return s;
  const std::array<std::uint8_t, 2> data{outputs.bits, 0};
  return apply_command(*v, Bytes(data), outputs, issuer, now);
}

Status DioRack::command(MacId mac, const rack::NodeCommand& command, std::string_view issuer,
                        TimePoint now) {
  if (const auto* outputs = command.as<DioOutputs>()) {
    return this->command(mac, *outputs, issuer, now);
  }
  return refuse_other_form(mac, issuer);
}

namespace {

// Any change of what the sample shows is news.
class DioStateGate final : public rack::StateGate {
 public:
  using StateGate::StateGate;

 private:
  using Seen = std::tuple<bool, bool, std::uint8_t, std::uint8_t, std::int16_t, bool, std::uint8_t,
                          std::string>;
  static Seen seen(const rack::NodeView& view) {
    const auto& v = static_cast<const DioView&>(view);
    return {v.online,          v.has_inputs,   v.inputs,          v.module_status,
            v.analog_input_mv, v.outputs_idle, v.outputs_applied, v.commanded_by};
  }
  bool changed(const rack::NodeView& view) const override { return seen(view) != last_; }
  void record(const rack::NodeView& view) override { last_ = seen(view); }
  Seen last_;
};

}  // namespace

std::unique_ptr<rack::StateGate> DioRack::state_gate(const rack::PublishPolicy& policy) const {
  return std::make_unique<DioStateGate>(policy);
}

}  // namespace dnbridge::test::dio
