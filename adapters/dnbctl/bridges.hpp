#pragma once
// The bridges on the domain as discovery sees them: every participant named
// "dnbridge <rack>" (DCPSParticipant built-in topic), so that a bridge shows
// even before anything it publishes has arrived.
#include <map>
#include <string>
#include <vector>

#include "adapters/dds/discovered_participants.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dnbctl/client.hpp"

namespace dnbridge::dnbctl {

class Bridges {
 public:
  // Discovery's news wakes the client's waits. Throws dds::Error.
  explicit Bridges(Client& client);

  // Takes what discovery reported since the last call.
  void refresh();
  // The live bridge participants per rack name: where each runs, "HOST
  // (pid PID)" from its user data (dds::host_user_data), or "" when it
  // says nothing.
  std::map<std::string, std::vector<std::string>> live() const;

 private:
  struct Seen {
    std::string rack;
    std::string where;
    bool alive = true;
  };
  dds::DiscoveredParticipants reader_;
  dds::ReadCondition data_;
  std::map<dds::ParticipantGuid, Seen> seen_;  // bridges only
};

}  // namespace dnbridge::dnbctl
