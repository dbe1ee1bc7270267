#include "adapters/dnbctl/commander.hpp"

#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"

namespace dnbridge::dnbctl {

Commander::Commander(Client& client, std::int32_t strength, const std::string& rack)
    : topic_(client.participant()),
      writer_(client.participant(), topic_,
              dds::command_writer_qos(std::vector{dds::rack_partition(rack)}, strength, kLease)) {}

bool Commander::wait_matched(Client& client, Deadline deadline) {
  return client.wait_until(deadline, [&] {
    auto n = writer_.matched_subscriptions();
    return n.ok() && *n > 0;
  });
}

std::uint32_t Commander::matched() const { return writer_.matched_subscriptions().value_or(0); }

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

}  // namespace dnbridge::dnbctl
