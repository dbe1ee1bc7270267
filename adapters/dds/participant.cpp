#include "adapters/dds/participant.hpp"

#include "adapters/dds/qos.hpp"

namespace dnbridge::dds {

std::string participant_name(std::string_view rack) {
  std::string name = "dnbridge ";
  name += rack;
  return name;
}

namespace {

dds_entity_t create_participant(dds_domainid_t domain, const std::string& name) {
  Qos qos;
  qos.entity_name(name);
  return check(dds_create_participant(domain, qos.get(), nullptr),
               "creating the participant of domain " + std::to_string(domain));
}

}  // namespace

Participant::Participant(dds_domainid_t domain, std::string_view rack)
    : Entity(create_participant(domain, participant_name(rack))), domain_(domain) {}

Participant::Participant(dds_domainid_t domain, ClientName client)
    : Entity(create_participant(domain, std::string(client.name))), domain_(domain) {}

}  // namespace dnbridge::dds
