#pragma once
// Waiting on our own thread for DDS events, instead of Cyclone listeners
// (which run on Cyclone's threads). Entities are attached with a token of the
// caller's choice; wait() hands back the tokens of those that triggered.
#include <dds/dds.h>

#include <cstddef>
#include <span>
#include <vector>

#include "adapters/dds/entity.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/time.hpp"

namespace dnbridge::dds {

// Set from any thread to wake a waitset it is attached to; stays triggered
// until taken.
class GuardCondition : public Entity {
 public:
  explicit GuardCondition(const Participant& participant);
  Status trigger() const noexcept { return to_status(dds_set_guardcondition(handle(), true)); }
  // Whether it was triggered; resets it.
  Result<bool> take_triggered() const noexcept;
};

class WaitSet : public Entity {
 public:
  using Token = dds_attach_t;

  explicit WaitSet(const Participant& participant);

  // Attaches a read condition, guard condition, or an entity's status
  // condition (a reader, a writer: see Entity::set_status_mask). Throws Error.
  void attach(const Entity& entity, Token token);
  Status detach(const Entity& entity) noexcept;

  // Blocks until something attached triggers or `timeout` passes; the
  // tokens of the triggered entities, empty on timeout. The span is valid
  // until the next wait().
  Result<std::span<const Token>> wait(Duration timeout) noexcept;

 private:
  std::vector<Token> triggered_;  // one slot per attached entity
};

}  // namespace dnbridge::dds
