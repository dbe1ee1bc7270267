#pragma once
// What the e2e client processes and their tests write to the embedded
// default rack ("sim-rack", port "A"): a pump command, and the explicit
// request they send most.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topics.hpp"

namespace dnbridge::e2e {

// The embedded default rack, and its partition of commands and requests.
inline constexpr const char* kSimRack = "sim-rack";
inline std::vector<std::string> sim_rack_partitions() { return dds::rack_partitions(kSimRack); }

inline dds::Owned<dnbridge_PumpCommand> pump_command(unsigned mac, bool pump_on, bool n2,
                                                     std::uint16_t analog,
                                                     std::string_view issuer) {
  dds::Owned<dnbridge_PumpCommand> c;
  dds::set_string(c->rack, kSimRack);
  dds::set_string(c->port, "A");
  c->mac = static_cast<std::uint8_t>(mac);
  c->pump_on = pump_on;
  c->n2_ballast_on = n2;
  c->analog_output_raw = analog;
  dds::set_string(c->issuer, issuer);
  return c;
}

// Get_Attribute_Single of the Identity vendor (class 1, instance 1,
// attribute 1) of node `mac`.
inline dds::Owned<dnbridge_ExplicitRequest> get_vendor(const std::string& requester,
                                                       std::uint32_t txid, unsigned mac) {
  dds::Owned<dnbridge_ExplicitRequest> r;
  dds::set_string(r->requester, requester);
  r->txid = txid;
  r->command = dnbridge_COMMAND_EXECUTE;
  dds::set_string(r->rack, kSimRack);
  dds::set_string(r->port, "A");
  r->mac = static_cast<std::uint8_t>(mac);
  r->service = 0x0E;
  r->class_id = 1;
  r->instance_id = 1;
  r->has_attribute = true;
  r->attribute_id = 1;
  return r;
}

}  // namespace dnbridge::e2e
