#include "profiles/dio/dio_topics.hpp"

#include <fmt/format.h>

#include <string>
#include <vector>

#include "adapters/daemon/samples.hpp"
#include "adapters/dds/fields.hpp"

namespace dnbridge::test::dio {

void fill_dio_state(dnbridge_test_DioState& out, std::string_view rack, std::string_view port,
                    const DioView& v) {
  dds::set_string(out.rack, rack);
  dds::set_string(out.port, port);
  out.mac = v.mac.value();
  dds::set_string(out.name, v.name);
  out.online = v.online;
  out.inputs_valid = v.online && v.has_inputs;
  out.inputs = out.inputs_valid ? v.inputs : 0;
  out.module_status = out.inputs_valid ? v.module_status : 0;
  out.analog_input_mv = out.inputs_valid ? v.analog_input_mv : 0;
  out.outputs_idle = v.outputs_idle;
  dds::set_string(out.idle_reason, v.idle_reason());
  out.outputs = v.outputs_idle ? 0 : v.outputs_applied;
  dds::set_string(out.commanded_by,
                  v.outputs_idle ? std::string_view{} : std::string_view(v.commanded_by));
}

void fill_dio_status(dnbridge_NodeStatus& out, std::string_view rack, std::string_view port,
                     const DioView& v, const port::NodeStatusView& status) {
  daemon::fill_node_common(out, rack, port, v, status);
  const auto unknown = dnbridge_SAFE_ACTION_UNKNOWN;
  out.safe_state_known = v.fault_outputs_read && v.idle_outputs_read;
  out.safe_state_source = dnbridge_SAFE_STATE_CONFIGURED;
  out.pump_on_fault = out.pump_on_idle = out.n2_ballast_on_fault = out.n2_ballast_on_idle =
      out.analog_output_on_fault = out.analog_output_on_idle = unknown;
  out.analog_output_fault_raw = out.analog_output_idle_raw = 0;
  dds::set_string(out.safe_state_text,
                  out.safe_state_known
                      ? fmt::format("outputs on a fault 0x{:02X}, when idle 0x{:02X}",
                                    *v.fault_outputs_read, *v.idle_outputs_read)
                      : std::string("not read yet"));
  dds::set_string(out.idle_reason, v.idle_reason());
}

rack::NodeCommand command_of(const dnbridge_test_DioCommand& c) {
  return rack::NodeCommand(DioOutputs{c.outputs});
}

std::span<const daemon::ProfileTopics> dio_profiles() {
  static const std::vector<daemon::ProfileTopics> profiles = [] {
    const auto bridge = daemon::bridge_profiles();
    std::vector<daemon::ProfileTopics> all(bridge.begin(), bridge.end());
    all.push_back(daemon::topics_of<dnbridge_test_DioState, DioView, dnbridge_test_DioCommand>(
        DioProfile::kName, true, {&fill_dio_state, &fill_dio_status, &command_of}));
    return all;
  }();
  return profiles;
}

}  // namespace dnbridge::test::dio
