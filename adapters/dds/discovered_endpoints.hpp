#pragma once
// The readers and writers discovery has found on the domain (the
// DCPSPublication and DCPSSubscription built-in topics), with what a bridge
// needs to tell why one does not match it: topic, type, partitions,
// liveliness lease, deadline. And a participant's own readers and writers,
// with the remote endpoints each has matched.
#include <dds/dds.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "adapters/dds/discovered_participants.hpp"
#include "adapters/dds/entity.hpp"
#include "adapters/dds/participant.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::dds {

// A GUID (participant, reader or writer), as discovery carries it.
using Guid = std::array<std::uint8_t, 16>;
std::string to_string(const Guid& guid);  // 32 hex digits, in groups

struct DiscoveredEndpoint {
  Guid guid{};
  Guid participant{};
  bool writer = false;  // a writer (DCPSPublication), else a reader
  bool alive = true;    // false: it is gone (only `guid` and `writer` are set)
  std::string topic;
  std::string type_name;
  std::vector<std::string> partitions;  // empty: the default partition
  // Its liveliness lease and deadline; none: infinite.
  std::optional<Duration> lease;
  std::optional<Duration> deadline;
  // Its XTypes type information equals the one given (TypeInfoCheck); none
  // when either side has none.
  std::optional<bool> same_type;
};

// A local topic's type information, to compare discovered endpoints with.
class TypeInfo {
 public:
  // Of `topic`, a topic entity (not owned).
  explicit TypeInfo(dds_entity_t topic);
  ~TypeInfo();
  TypeInfo(const TypeInfo&) = delete;
  TypeInfo& operator=(const TypeInfo&) = delete;
  // Whether `endpoint` (a built-in topic sample) has the same type
  // information, dependencies included; none when either side has none.
  std::optional<bool> same_as(const dds_builtintopic_endpoint_t& endpoint) const;

 private:
  dds_typeinfo_t* info_ = nullptr;
};

class DiscoveredEndpoints {
 public:
  // Readers of both built-in topics in `participant`. Throws Error.
  explicit DiscoveredEndpoints(const Participant& participant);

  // What discovery reported since the last take, the participant's own
  // endpoints included. `type_of` gives the local type information of a
  // topic name (null when it is not one of ours).
  template <class TypeOf>
  Result<std::vector<DiscoveredEndpoint>> take(TypeOf type_of) const {
    std::vector<DiscoveredEndpoint> out;
    if (auto s = take_from(publications_, true, out, type_of); !s) return s.error();
    if (auto s = take_from(subscriptions_, false, out, type_of); !s) return s.error();
    return out;
  }

  const Entity& publications() const { return publications_; }
  const Entity& subscriptions() const { return subscriptions_; }

 private:
  template <class TypeOf>
  static Status take_from(const Entity& reader, bool writer, std::vector<DiscoveredEndpoint>& out,
                          TypeOf type_of) {
    constexpr std::uint32_t kBatch = 16;
    for (;;) {
      void* samples[kBatch] = {};
      dds_sample_info_t infos[kBatch];
      const dds_return_t n = dds_take(reader.handle(), samples, infos, kBatch, kBatch);
      if (n < 0) return make_error_code(n);
      for (dds_return_t i = 0; i < n; ++i) {
        const auto* e = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
        out.push_back(endpoint_of(*e, infos[i], writer));
        if (out.back().alive && e->topic_name != nullptr) {
          if (const TypeInfo* local = type_of(std::string_view(e->topic_name))) {
            out.back().same_type = local->same_as(*e);
          }
        }
      }
      if (n > 0) (void)dds_return_loan(reader.handle(), samples, n);
      if (n < static_cast<dds_return_t>(kBatch)) return {};
    }
  }
  static DiscoveredEndpoint endpoint_of(const dds_builtintopic_endpoint_t& e,
                                        const dds_sample_info_t& info, bool writer);

  Entity publications_;
  Entity subscriptions_;
};

// One of a participant's own readers or writers.
struct LocalEndpoint {
  dds_entity_t handle = 0;
  bool writer = false;
  std::string topic;
  std::vector<std::string> partitions;  // its publisher's or subscriber's
  std::optional<Duration> deadline;     // offered or requested; none: infinite
  std::optional<Duration> lease;        // likewise
  std::vector<Guid> matched;            // the remote endpoints it has matched
};

// The readers and writers of `participant` (user topics only), each with
// what it has matched now.
std::vector<LocalEndpoint> local_endpoints(const Participant& participant);

// Whether two partition lists meet, as DDS matches them: a name in both, or
// a name one side's pattern (with '*' or '?') matches. Empty is the default
// partition, "".
bool partitions_meet(const std::vector<std::string>& a, const std::vector<std::string>& b);

}  // namespace dnbridge::dds
