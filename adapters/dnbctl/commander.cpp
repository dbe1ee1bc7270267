#include "adapters/dnbctl/commander.hpp"

namespace dnbridge::dnbctl {

void fill_command(dnbridge_PumpCommand& c, const Outputs& outputs) {
  c.pump_on = outputs.pump_on;
  c.n2_ballast_on = outputs.n2_ballast_on;
  c.analog_output_raw = outputs.analog_output_raw;
}

void fill_command(dnbridge_DeviceCommand& c, const DeviceOutputs& outputs) {
  dds::set_octets(c.outputs, outputs.bytes);
  if (!outputs.bytes.empty() || outputs.fields.empty()) return;
  auto& seq = c.fields;
  seq._length = seq._maximum = static_cast<std::uint32_t>(outputs.fields.size());
  seq._release = true;
  seq._buffer = dds_sequence_dnbridge_DeviceFieldValue_allocbuf(outputs.fields.size());
  for (std::size_t i = 0; i < outputs.fields.size(); ++i) {
    seq._buffer[i].name = nullptr;
    dds::set_string(seq._buffer[i].name, outputs.fields[i].first);
    seq._buffer[i].value = outputs.fields[i].second;
  }
}

}  // namespace dnbridge::dnbctl
