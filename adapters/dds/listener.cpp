#include "adapters/dds/listener.hpp"

#include <new>

namespace dnbridge::dds {

DataListener::DataListener(std::function<void()> on_data)
    : on_data_(std::move(on_data)), listener_(dds_create_listener(this)) {
  if (listener_ == nullptr) throw std::bad_alloc();
  dds_lset_data_available(listener_, &DataListener::call);
}

DataListener::~DataListener() { dds_delete_listener(listener_); }

Status DataListener::detach(const Entity& reader) noexcept {
  return to_status(dds_set_listener(reader.handle(), nullptr));
}

void DataListener::call(dds_entity_t, void* self) { static_cast<DataListener*>(self)->on_data_(); }

}  // namespace dnbridge::dds
