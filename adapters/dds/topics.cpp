#include "adapters/dds/topics.hpp"

namespace dnbridge::dds {
namespace {

// How long a reliable write may wait for room in a full reader history
// before it fails with DDS_RETCODE_TIMEOUT; short, as writes are made from
// the bridge's event loop.
constexpr Duration kMaxBlocking = milliseconds(100);

Qos state_common() {
  Qos qos;
  qos.reliable(kMaxBlocking)
      .durability(Durability::kTransientLocal)
      .keep_last(1)
      .liveliness(Liveliness::kAutomatic)
      .destination_order_by_source_timestamp();
  return qos;
}

Qos command_common() {
  Qos qos;
  qos.reliable(kMaxBlocking)
      .durability(Durability::kVolatile)
      .keep_last(1)
      .exclusive_ownership()
      .destination_order_by_source_timestamp();
  return qos;
}

// A reply that cannot be written at once (a reader somewhere does not
// acknowledge) is given up soon; the requester repeats and gets it again.
constexpr Duration kReplyMaxBlocking = milliseconds(10);

// A reply writer keeping the last `history` replies of its one instance,
// for late readers and for resends alike.
Qos reply_writer_keeping(int32_t history) {
  Qos qos;
  qos.reliable(kReplyMaxBlocking)
      .durability(Durability::kTransientLocal)
      .keep_last(history)
      .durability_service_keep_last(history);
  return qos;
}

}  // namespace

Qos state_writer_qos(Duration deadline) {
  Qos qos = state_common();
  // Written from the port loops: a write must fail rather than wait.
  qos.reliable(Duration::zero());
  qos.deadline(deadline).autodispose_unregistered_instances(false);
  return qos;
}

Qos state_reader_qos(std::optional<Duration> deadline) {
  Qos qos = state_common();
  qos.deadline(deadline.value_or(kInfinite));
  return qos;
}

std::string rack_partition(std::string_view rack) {
  std::string name = "dnbridge/";
  name += rack;
  return name;
}

std::vector<std::string> rack_partitions(std::span<const std::string> racks) {
  std::vector<std::string> out;
  for (const auto& r : racks) out.push_back(rack_partition(r));
  return out;
}

std::vector<std::string> rack_partitions(std::string_view rack) { return {rack_partition(rack)}; }

Qos command_writer_qos(std::span<const std::string> partitions, int32_t strength, Duration lease,
                       std::optional<Duration> deadline) {
  Qos qos = command_common();
  qos.partitions(partitions);
  qos.ownership_strength(strength)
      .liveliness(Liveliness::kAutomatic, lease)
      .autodispose_unregistered_instances(false);
  if (deadline) qos.deadline(*deadline);
  return qos;
}

Qos command_reader_qos(std::span<const std::string> partitions, Duration max_lease,
                       std::optional<Duration> deadline) {
  Qos qos = command_common();
  qos.partitions(partitions);
  // Commands in the order they arrive, whatever their source timestamps:
  // ordered by those, one commander whose clock runs ahead would have every
  // later sample dropped, its own unregistration included, and hold its
  // pumps long after it left. (Any writer's order is compatible with this.)
  qos.destination_order_by_source_timestamp(false);
  // A writer matches when its lease is at most the one requested (any
  // liveliness kind: automatic is the weakest asked for); its own lease
  // still decides when the reader sees it lose liveliness.
  qos.liveliness(Liveliness::kAutomatic, max_lease);
  qos.deadline(deadline.value_or(kInfinite));
  return qos;
}

Qos request_writer_qos(std::span<const std::string> partitions) {
  Qos qos;
  qos.partitions(partitions);
  qos.reliable(kMaxBlocking)
      .durability(Durability::kVolatile)
      .keep_all()
      .resource_limits(kRequestWriterMaxSamples, kRequestWriterMaxSamples, kExplicitHistoryDepth);
  return qos;
}

Qos request_reader_qos(std::span<const std::string> partitions) {
  Qos qos;
  qos.partitions(partitions);
  qos.reliable(kMaxBlocking).durability(Durability::kVolatile).keep_last(kExplicitHistoryDepth);
  return qos;
}

Qos reply_writer_qos(std::span<const std::string> partitions) {
  Qos qos = reply_writer_keeping(kReplyHistory);
  qos.partitions(partitions);
  return qos;
}

Qos scan_reply_writer_qos(std::span<const std::string> partitions) {
  Qos qos = reply_writer_keeping(kScanReplyHistory);
  qos.partitions(partitions);
  return qos;
}

Qos reply_reader_qos(std::span<const std::string> partitions) {
  Qos qos;
  qos.partitions(partitions);
  qos.reliable(kMaxBlocking).durability(Durability::kTransientLocal).keep_all();
  return qos;
}

}  // namespace dnbridge::dds
