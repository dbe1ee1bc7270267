#pragma once
// A move-only builder over dds_qos_t. Setters chain; durations are
// dnbridge::Duration; kInfinite (time.hpp) stands for DDS_INFINITY.
#include <dds/dds.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "adapters/dds/time.hpp"

namespace dnbridge::dds {

enum class Durability { kVolatile, kTransientLocal };
enum class Liveliness { kAutomatic, kManualByParticipant, kManualByTopic };

class Qos {
 public:
  Qos();  // every policy unset: Cyclone's defaults apply
  ~Qos();
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;
  Qos(Qos&& other) noexcept;
  Qos& operator=(Qos&& other) noexcept;

  // Reliable; a writer blocks at most max_blocking when the history of a
  // keep-all writer or of a reader is full.
  Qos& reliable(Duration max_blocking = milliseconds(100));
  Qos& best_effort();
  Qos& durability(Durability kind);
  Qos& keep_last(int32_t depth);
  Qos& keep_all();
  // Per-reader (or writer) history bounds; -1 is unlimited.
  Qos& resource_limits(int32_t max_samples, int32_t max_instances,
                       int32_t max_samples_per_instance);
  // What a transient-local writer keeps for late joiners, per instance.
  Qos& durability_service_keep_last(int32_t depth);
  Qos& deadline(Duration period);
  Qos& liveliness(Liveliness kind, Duration lease = kInfinite);
  Qos& exclusive_ownership(bool exclusive = true);
  Qos& ownership_strength(int32_t strength);
  Qos& destination_order_by_source_timestamp(bool by_source = true);
  Qos& entity_name(const std::string& name);
  // The partitions of the writer's publisher or the reader's subscriber.
  Qos& partitions(std::span<const std::string> names);
  Qos& lifespan(Duration d);
  // Whether deleting a writer (or unregistering an instance) also disposes.
  Qos& autodispose_unregistered_instances(bool autodispose);
  Qos& userdata(std::span<const std::byte> data);
  // A property (name, value) of the property policy, e.g. DDS Security's.
  Qos& property(const std::string& name, const std::string& value);

  const dds_qos_t* get() const noexcept { return qos_; }

 private:
  dds_qos_t* qos_;
};

}  // namespace dnbridge::dds
