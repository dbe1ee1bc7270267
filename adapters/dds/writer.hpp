#pragma once
// A typed data writer. Creation throws Error; every operation after that
// returns a Status or Result and never throws.
#include <dds/dds.h>

#include <cstdint>
#include <string>

#include "adapters/dds/entity.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/qos.hpp"
#include "adapters/dds/time.hpp"
#include "adapters/dds/topic.hpp"

namespace dnbridge::dds {

template <class T>
class Writer : public Entity {
 public:
  Writer(const Participant& participant, const Topic<T>& topic, const Qos& qos)
      : Entity(check(
            dds_create_writer(participant.handle(), topic.handle(), qos.get(), nullptr),
            std::string("creating a writer of ") + TopicTraits<T>::kDescriptor->m_typename)) {}

  // Stamped with Cyclone's clock now.
  Status write(const T& sample) const noexcept { return to_status(dds_write(handle(), &sample)); }
  // Stamped with `source_time` (e.g. when the CAN frame the sample comes from
  // was received). With destination order by source timestamp, a reader drops
  // a sample older than the one it holds for the instance.
  Status write(const T& sample, Timestamp source_time) const noexcept {
    return to_status(dds_write_ts(handle(), &sample, to_dds(source_time)));
  }

  // The writer stops updating the instance whose key members `key` holds;
  // when no writer is left the readers see NOT_ALIVE_NO_WRITERS (or DISPOSED,
  // if the writer's QoS autodisposes).
  Status unregister_instance(const T& key) const noexcept {
    return to_status(dds_unregister_instance(handle(), &key));
  }
  Status unregister_instance(const T& key, Timestamp source_time) const noexcept {
    return to_status(dds_unregister_instance_ts(handle(), &key, to_dds(source_time)));
  }
  Status dispose(const T& key) const noexcept { return to_status(dds_dispose(handle(), &key)); }
  Status dispose(const T& key, Timestamp source_time) const noexcept {
    return to_status(dds_dispose_ts(handle(), &key, to_dds(source_time)));
  }

  // Until every matched reliable reader acknowledged everything written;
  // DDS_RETCODE_TIMEOUT otherwise.
  Status wait_for_acks(Duration timeout) const noexcept {
    return to_status(dds_wait_for_acks(handle(), to_dds(timeout)));
  }

  Result<uint32_t> matched_subscriptions() const noexcept {
    auto status = publication_matched();
    if (!status) return status.error();
    return status->current_count;
  }

  // Status getters read and reset the status' "change" counts.
  Result<dds_publication_matched_status_t> publication_matched() const noexcept {
    dds_publication_matched_status_t s{};
    return result(dds_get_publication_matched_status(handle(), &s), s);
  }
  Result<dds_offered_deadline_missed_status_t> offered_deadline_missed() const noexcept {
    dds_offered_deadline_missed_status_t s{};
    return result(dds_get_offered_deadline_missed_status(handle(), &s), s);
  }
  Result<dds_liveliness_lost_status_t> liveliness_lost() const noexcept {
    dds_liveliness_lost_status_t s{};
    return result(dds_get_liveliness_lost_status(handle(), &s), s);
  }
  Result<dds_offered_incompatible_qos_status_t> offered_incompatible_qos() const noexcept {
    dds_offered_incompatible_qos_status_t s{};
    return result(dds_get_offered_incompatible_qos_status(handle(), &s), s);
  }

 private:
  template <class S>
  static Result<S> result(dds_return_t rc, const S& s) noexcept {
    if (rc < 0) return make_error_code(rc);
    return s;
  }
};

}  // namespace dnbridge::dds
