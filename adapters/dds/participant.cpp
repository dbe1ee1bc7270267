#include "adapters/dds/participant.hpp"

#include "adapters/dds/qos.hpp"

namespace dnbridge::dds {

std::string participant_name(std::string_view rack) {
  std::string name = "dnbridge ";
  name += rack;
  return name;
}

Participant::Participant(dds_domainid_t domain, std::string_view rack)
    : Entity([&] {
        Qos qos;
        qos.entity_name(participant_name(rack));
        return check(dds_create_participant(domain, qos.get(), nullptr),
                     "creating the participant of domain " + std::to_string(domain));
      }()),
      domain_(domain) {}

}  // namespace dnbridge::dds
