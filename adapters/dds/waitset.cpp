#include "adapters/dds/waitset.hpp"

#include <algorithm>

namespace dnbridge::dds {

GuardCondition::GuardCondition(const Participant& participant)
    : Entity(check(dds_create_guardcondition(participant.handle()), "creating a guard condition")) {
}

Result<bool> GuardCondition::take_triggered() const noexcept {
  bool triggered = false;
  const dds_return_t rc = dds_take_guardcondition(handle(), &triggered);
  if (rc < 0) return make_error_code(rc);
  return triggered;
}

WaitSet::WaitSet(const Participant& participant)
    : Entity(check(dds_create_waitset(participant.handle()), "creating a waitset")) {}

void WaitSet::attach(const Entity& entity, Token token) {
  check(dds_waitset_attach(handle(), entity.handle(), token), "attaching to a waitset");
  triggered_.push_back(0);
}

Status WaitSet::detach(const Entity& entity) noexcept {
  const dds_return_t rc = dds_waitset_detach(handle(), entity.handle());
  if (rc >= 0 && !triggered_.empty()) triggered_.pop_back();
  return to_status(rc);
}

Result<std::span<const WaitSet::Token>> WaitSet::wait(Duration timeout) noexcept {
  const dds_return_t n =
      dds_waitset_wait(handle(), triggered_.data(), triggered_.size(), to_dds(timeout));
  if (n < 0) return make_error_code(n);
  const std::size_t count = std::min(static_cast<std::size_t>(n), triggered_.size());
  return std::span<const Token>(triggered_.data(), count);
}

}  // namespace dnbridge::dds
