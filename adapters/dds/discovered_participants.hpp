#pragma once
// The participants discovery has found on the domain (the DCPSParticipant
// built-in topic), with the names they gave themselves through the
// entity-name QoS policy: how a tool finds every rack's bridge
// ("dnbridge <rack>", participant.hpp), even one that publishes nothing yet.
#include <dds/dds.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/dds/entity.hpp"
#include "adapters/dds/participant.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::dds {

// A participant's GUID, as discovery carries it.
using ParticipantGuid = std::array<std::uint8_t, 16>;

struct DiscoveredParticipant {
  ParticipantGuid guid{};
  std::string name;       // empty when it gave none (or the sample only tells it left)
  std::string user_data;  // its USER_DATA as text (host_user_data), when it gave some
  bool alive = true;      // false: it left the domain (or was lost)
  // Its lease (how long it stays known without a sign of life); none:
  // infinite, or not told.
  std::optional<Duration> lease;
};

class DiscoveredParticipants : public Entity {
 public:
  // A reader of the built-in topic in `participant`. Throws Error.
  explicit DiscoveredParticipants(const Participant& participant);

  // Everything discovery reported since the last take: participants that
  // appeared (the participant itself included) and participants that left.
  Result<std::vector<DiscoveredParticipant>> take() const;
};

// The rack whose bridge a participant is, from its name "dnbridge <rack>"
// (participant_name); none for any other name.
std::optional<std::string> bridge_rack(std::string_view participant_name);

}  // namespace dnbridge::dds
