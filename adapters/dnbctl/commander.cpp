#include "adapters/dnbctl/commander.hpp"

#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"

namespace dnbridge::dnbctl {

Status Commander::write(const NodeKey& key, const Outputs& outputs, const std::string& issuer) {
  dds::Owned<dnbridge_PumpCommand> c;
  dds::set_string(c->rack, key.rack);
  dds::set_string(c->port, key.port);
  c->mac = key.mac;
  c->pump_on = outputs.pump_on;
  c->n2_ballast_on = outputs.n2_ballast_on;
  c->analog_output_raw = outputs.analog_output_raw;
  dds::set_string(c->issuer, issuer);
  return writer_.write(*c);
}

Status DeviceCommander::write(const NodeKey& key, const DeviceOutputs& outputs,
                              const std::string& issuer) {
  dds::Owned<dnbridge_DeviceCommand> c;
  dds::set_string(c->rack, key.rack);
  dds::set_string(c->port, key.port);
  c->mac = key.mac;
  dds::set_octets(c->outputs, outputs.bytes);
  if (outputs.bytes.empty() && !outputs.fields.empty()) {
    auto& seq = c->fields;
    seq._length = seq._maximum = static_cast<std::uint32_t>(outputs.fields.size());
    seq._release = true;
    seq._buffer = dds_sequence_dnbridge_DeviceFieldValue_allocbuf(outputs.fields.size());
    for (std::size_t i = 0; i < outputs.fields.size(); ++i) {
      seq._buffer[i].name = nullptr;
      dds::set_string(seq._buffer[i].name, outputs.fields[i].first);
      seq._buffer[i].value = outputs.fields[i].second;
    }
  }
  dds::set_string(c->issuer, issuer);
  return writer_.write(*c);
}

}  // namespace dnbridge::dnbctl
