#pragma once
// The explicit request the e2e clients send most: Get_Attribute_Single of
// the Identity vendor (class 1, instance 1, attribute 1) of a node of the
// embedded default rack ("sim-rack", port "A").
#include <cstdint>
#include <string>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topics.hpp"

namespace dnbridge::e2e {

inline dds::Owned<dnbridge_ExplicitRequest> get_vendor(const std::string& requester,
                                                       std::uint32_t txid, unsigned mac) {
  dds::Owned<dnbridge_ExplicitRequest> r;
  dds::set_string(r->requester, requester);
  r->txid = txid;
  r->command = dnbridge_COMMAND_EXECUTE;
  dds::set_string(r->rack, "sim-rack");
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
