#pragma once
// A Cyclone DDS listener for DATA_AVAILABLE only: `on_data` runs on
// Cyclone's own thread (the one that delivers the sample), each time a
// reader it was given to at creation gets data. Cyclone holds up delivery on
// that thread until it returns: it must be short and never block (take, hand
// over, wake; never wait for anything). Everything else waits on a waitset
// (waitset.hpp).
#include <dds/dds.h>

#include <functional>

#include "adapters/dds/entity.hpp"

namespace dnbridge::dds {

class DataListener {
 public:
  explicit DataListener(std::function<void()> on_data);
  ~DataListener();
  DataListener(const DataListener&) = delete;
  DataListener& operator=(const DataListener&) = delete;

  const dds_listener_t* get() const noexcept { return listener_; }

  // No call of `on_data` for `reader` after this returns: it waits for one
  // in progress (dds_set_listener). Call it before anything `on_data` uses
  // goes away.
  static Status detach(const Entity& reader) noexcept;

 private:
  static void call(dds_entity_t reader, void* self);

  std::function<void()> on_data_;
  dds_listener_t* listener_;
};

}  // namespace dnbridge::dds
