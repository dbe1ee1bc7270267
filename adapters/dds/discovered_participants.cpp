#include "adapters/dds/discovered_participants.hpp"

#include <cstring>

namespace dnbridge::dds {

DiscoveredParticipants::DiscoveredParticipants(const Participant& participant)
    : Entity(check(dds_create_reader(participant.handle(), DDS_BUILTIN_TOPIC_DCPSPARTICIPANT,
                                     nullptr, nullptr),
                   "creating a reader of the DCPSParticipant built-in topic")) {}

Result<std::vector<DiscoveredParticipant>> DiscoveredParticipants::take() const {
  std::vector<DiscoveredParticipant> out;
  constexpr std::uint32_t kBatch = 16;
  for (;;) {
    // Built-in topic samples are loaned: copied out, then the loan returned.
    void* samples[kBatch] = {};
    dds_sample_info_t infos[kBatch];
    const dds_return_t n = dds_take(handle(), samples, infos, kBatch, kBatch);
    if (n < 0) return make_error_code(n);
    for (dds_return_t i = 0; i < n; ++i) {
      const auto* p = static_cast<const dds_builtintopic_participant_t*>(samples[i]);
      DiscoveredParticipant d;
      static_assert(sizeof d.guid == sizeof p->key);
      std::memcpy(d.guid.data(), &p->key, sizeof d.guid);
      d.alive = infos[i].instance_state == DDS_IST_ALIVE;
      char* name = nullptr;
      if (infos[i].valid_data && p->qos != nullptr && dds_qget_entity_name(p->qos, &name) &&
          name != nullptr) {
        d.name = name;
        dds_free(name);
      }
      void* data = nullptr;
      std::size_t size = 0;
      if (infos[i].valid_data && p->qos != nullptr && dds_qget_userdata(p->qos, &data, &size) &&
          data != nullptr) {
        d.user_data.assign(static_cast<const char*>(data), size);
        dds_free(data);
      }
      dds_liveliness_kind_t kind{};
      dds_duration_t lease = DDS_INFINITY;
      if (infos[i].valid_data && p->qos != nullptr && dds_qget_liveliness(p->qos, &kind, &lease) &&
          lease != DDS_INFINITY) {
        d.lease = std::chrono::nanoseconds(lease);
      }
      out.push_back(std::move(d));
    }
    if (n > 0) (void)dds_return_loan(handle(), samples, n);
    if (n < static_cast<dds_return_t>(kBatch)) return out;
  }
}

std::optional<std::string> bridge_rack(std::string_view name) {
  const std::string prefix = participant_name("");
  if (name.size() <= prefix.size() || !name.starts_with(prefix)) return std::nullopt;
  return std::string(name.substr(prefix.size()));
}

}  // namespace dnbridge::dds
