#pragma once
// A domain participant of one rack's bridge (or of a client), named through
// the entity-name QoS policy so that tools show which rack it serves, with
// the QoS properties it is given (DDS Security's, adapters/security).
#include <dds/dds.h>

#include <string>
#include <string_view>
#include <vector>

#include "adapters/dds/entity.hpp"

namespace dnbridge::dds {

// A QoS property of a participant (name, value), e.g. "dds.sec.auth.identity_ca".
struct Property {
  std::string name;
  std::string value;
};
using Properties = std::vector<Property>;

class Participant : public Entity {
 public:
  // Joins `domain` as "dnbridge <rack>", with the bridge's domain settings
  // when this process is the first in it (participant.cpp). Throws Error;
  // when Cyclone refuses the participant, the message has the reason Cyclone
  // logged (a DDS Security plugin's, for instance).
  // `user_data`: the participant's USER_DATA QoS (host_user_data()), which
  // discovery carries to every participant and tool.
  Participant(dds_domainid_t domain, std::string_view rack, const Properties& properties = {},
              std::string_view user_data = {});

  // A participant that is not a bridge (a client such as dnbctl), named as
  // given, so that tools never mistake it for a rack's bridge. Throws Error.
  struct ClientName {
    std::string_view name;
  };
  Participant(dds_domainid_t domain, ClientName client, const Properties& properties = {},
              std::string_view user_data = {});

  // Deletes the participant, and the domain it created if no other
  // participant is left in it.
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  dds_domainid_t domain() const noexcept { return domain_; }

  // A participant and the domain created for it (0: it joined one).
  struct Created {
    dds_entity_t participant;
    dds_entity_t domain;
  };

 private:
  Participant(Created created, dds_domainid_t domain);

  dds_domainid_t domain_;
  dds_entity_t own_domain_;
};

// "dnbridge <rack>": the participant name of a rack's bridge.
std::string participant_name(std::string_view rack);

// What a participant says of where it runs, as its USER_DATA: lines
// "host=HOST", "pid=PID" and "version=VERSION" (this host's name and this
// process's id), so that DDS tools and Wireshark's RTPS view show which host
// a rack's bridge is on.
std::string host_user_data(std::string_view version);
// A field of such user data ("host"); empty when absent.
std::string user_data_field(std::string_view user_data, std::string_view key);

}  // namespace dnbridge::dds
