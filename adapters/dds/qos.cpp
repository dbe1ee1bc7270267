#include "adapters/dds/qos.hpp"

#include <new>
#include <utility>
#include <vector>

namespace dnbridge::dds {

Qos::Qos() : qos_(dds_create_qos()) {
  if (qos_ == nullptr) throw std::bad_alloc();
}

Qos::~Qos() {
  if (qos_ != nullptr) dds_delete_qos(qos_);
}

Qos::Qos(Qos&& other) noexcept : qos_(std::exchange(other.qos_, nullptr)) {}

Qos& Qos::operator=(Qos&& other) noexcept {
  if (this != &other) {
    if (qos_ != nullptr) dds_delete_qos(qos_);
    qos_ = std::exchange(other.qos_, nullptr);
  }
  return *this;
}

Qos& Qos::reliable(Duration max_blocking) {
  dds_qset_reliability(qos_, DDS_RELIABILITY_RELIABLE, to_dds(max_blocking));
  return *this;
}

Qos& Qos::best_effort() {
  dds_qset_reliability(qos_, DDS_RELIABILITY_BEST_EFFORT, 0);
  return *this;
}

Qos& Qos::durability(Durability kind) {
  dds_qset_durability(qos_, kind == Durability::kTransientLocal ? DDS_DURABILITY_TRANSIENT_LOCAL
                                                                : DDS_DURABILITY_VOLATILE);
  return *this;
}

Qos& Qos::keep_last(int32_t depth) {
  dds_qset_history(qos_, DDS_HISTORY_KEEP_LAST, depth);
  return *this;
}

Qos& Qos::keep_all() {
  dds_qset_history(qos_, DDS_HISTORY_KEEP_ALL, DDS_LENGTH_UNLIMITED);
  return *this;
}

Qos& Qos::resource_limits(int32_t max_samples, int32_t max_instances,
                          int32_t max_samples_per_instance) {
  dds_qset_resource_limits(qos_, max_samples, max_instances, max_samples_per_instance);
  return *this;
}

Qos& Qos::durability_service_keep_last(int32_t depth) {
  dds_qset_durability_service(qos_, 0, DDS_HISTORY_KEEP_LAST, depth, DDS_LENGTH_UNLIMITED,
                              DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  return *this;
}

Qos& Qos::deadline(Duration period) {
  dds_qset_deadline(qos_, to_dds(period));
  return *this;
}

Qos& Qos::liveliness(Liveliness kind, Duration lease) {
  dds_liveliness_kind_t k = DDS_LIVELINESS_AUTOMATIC;
  if (kind == Liveliness::kManualByParticipant) k = DDS_LIVELINESS_MANUAL_BY_PARTICIPANT;
  if (kind == Liveliness::kManualByTopic) k = DDS_LIVELINESS_MANUAL_BY_TOPIC;
  dds_qset_liveliness(qos_, k, to_dds(lease));
  return *this;
}

Qos& Qos::exclusive_ownership(bool exclusive) {
  dds_qset_ownership(qos_, exclusive ? DDS_OWNERSHIP_EXCLUSIVE : DDS_OWNERSHIP_SHARED);
  return *this;
}

Qos& Qos::ownership_strength(int32_t strength) {
  dds_qset_ownership_strength(qos_, strength);
  return *this;
}

Qos& Qos::destination_order_by_source_timestamp(bool by_source) {
  dds_qset_destination_order(qos_, by_source ? DDS_DESTINATIONORDER_BY_SOURCE_TIMESTAMP
                                             : DDS_DESTINATIONORDER_BY_RECEPTION_TIMESTAMP);
  return *this;
}

Qos& Qos::partitions(std::span<const std::string> names) {
  std::vector<const char*> c;
  c.reserve(names.size());
  for (const auto& n : names) c.push_back(n.c_str());
  dds_qset_partition(qos_, static_cast<uint32_t>(c.size()), c.data());
  return *this;
}

Qos& Qos::entity_name(const std::string& name) {
  dds_qset_entity_name(qos_, name.c_str());
  return *this;
}

Qos& Qos::property(const std::string& name, const std::string& value) {
  dds_qset_prop(qos_, name.c_str(), value.c_str());
  return *this;
}

Qos& Qos::lifespan(Duration d) {
  dds_qset_lifespan(qos_, to_dds(d));
  return *this;
}

Qos& Qos::autodispose_unregistered_instances(bool autodispose) {
  dds_qset_writer_data_lifecycle(qos_, autodispose);
  return *this;
}

Qos& Qos::userdata(std::span<const std::byte> data) {
  dds_qset_userdata(qos_, data.data(), data.size());
  return *this;
}

}  // namespace dnbridge::dds
