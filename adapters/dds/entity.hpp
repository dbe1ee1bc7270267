#pragma once
// Ownership of Cyclone DDS entities and the two ways DDS failures are told:
// setting things up throws dds::Error (caught in main() with a clear message);
// operations on the data path return a Status/Result whose error_code carries
// the dds_return_t in the "dds" category, and never throw.
#include <dds/dds.h>

#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>

#include "bridge/common/result.hpp"

namespace dnbridge::dds {

// A failed set-up step: what was attempted and what Cyclone answered.
class Error : public std::runtime_error {
 public:
  Error(std::string_view attempted, dds_return_t code);
  // With the reason Cyclone gave elsewhere (its log) instead of the code's name.
  Error(std::string_view attempted, dds_return_t code, std::string_view reason);
  dds_return_t code() const noexcept { return code_; }

 private:
  dds_return_t code_;
};

// dds_return_t values as std::error_code (message: dds_strretcode).
const std::error_category& dds_category() noexcept;
inline std::error_code make_error_code(dds_return_t code) noexcept {
  return {static_cast<int>(code), dds_category()};
}

// OK or the error of a run-time call.
inline Status to_status(dds_return_t code) noexcept {
  if (code >= 0) return {};
  return make_error_code(code);
}

// Throws Error unless `result` (an entity or a return code) is >= 0.
dds_entity_t check(dds_entity_t result, std::string_view attempted);

// Sole owner of one DDS entity: deletes it (and with it its children) on
// destruction. Move-only, so an entity is deleted exactly once. Owners of
// children should be destroyed before the owner of their parent; if the
// parent went first, the child's dds_delete fails harmlessly.
class Entity {
 public:
  Entity() noexcept = default;
  explicit Entity(dds_entity_t handle) noexcept : handle_(handle) {}
  ~Entity() { reset(); }

  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  Entity(Entity&& other) noexcept : handle_(other.release()) {}
  Entity& operator=(Entity&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = other.release();
    }
    return *this;
  }

  dds_entity_t handle() const noexcept { return handle_; }
  explicit operator bool() const noexcept { return handle_ > 0; }

  // Gives up ownership without deleting.
  dds_entity_t release() noexcept {
    const dds_entity_t h = handle_;
    handle_ = 0;
    return h;
  }
  // Deletes the entity now (and its children).
  void reset() noexcept {
    if (handle_ > 0) (void)dds_delete(handle_);
    handle_ = 0;
  }

  // The entity's instance handle (a writer's is the publication_handle its
  // readers see in their sample info).
  Result<dds_instance_handle_t> instance_handle() const noexcept;

  // The name given with the entity-name QoS policy; empty when none.
  Result<std::string> entity_name() const;

  // Which statuses make the entity's status condition trigger in a waitset.
  Status set_status_mask(uint32_t mask) const noexcept {
    return to_status(dds_set_status_mask(handle_, mask));
  }

 private:
  dds_entity_t handle_ = 0;
};

}  // namespace dnbridge::dds
