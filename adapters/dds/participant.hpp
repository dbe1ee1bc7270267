#pragma once
// A domain participant of one rack's bridge (or of a client), named through
// the entity-name QoS policy so that tools show which rack it serves.
#include <dds/dds.h>

#include <string>
#include <string_view>

#include "adapters/dds/entity.hpp"

namespace dnbridge::dds {

class Participant : public Entity {
 public:
  // Joins `domain` as "dnbridge <rack>". Throws Error.
  Participant(dds_domainid_t domain, std::string_view rack);

  // A participant that is not a bridge (a client such as dnbctl), named as
  // given, so that tools never mistake it for a rack's bridge. Throws Error.
  struct ClientName {
    std::string_view name;
  };
  Participant(dds_domainid_t domain, ClientName client);

  dds_domainid_t domain() const noexcept { return domain_; }

 private:
  dds_domainid_t domain_;
};

// "dnbridge <rack>": the participant name of a rack's bridge.
std::string participant_name(std::string_view rack);

}  // namespace dnbridge::dds
