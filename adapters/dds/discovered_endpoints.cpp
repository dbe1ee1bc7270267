#include "adapters/dds/discovered_endpoints.hpp"

// ddsi_typelib.h (ddsi_typeinfo_equal) needs the QoS types of ddsi_xqos.h,
// which comes first.
#include <dds/ddsi/ddsi_xqos.h>
// After it.
#include <dds/ddsi/ddsi_typelib.h>
#include <fmt/format.h>
#include <fnmatch.h>

#include <algorithm>
#include <cstring>

namespace dnbridge::dds {
namespace {

Guid guid_of(const dds_guid_t& g) {
  Guid out{};
  static_assert(sizeof out == sizeof g.v);
  std::memcpy(out.data(), g.v, sizeof out);
  return out;
}

std::optional<Duration> finite(dds_duration_t d) {
  if (d == DDS_INFINITY) return std::nullopt;
  return std::chrono::nanoseconds(d);
}

std::vector<std::string> partitions_of(const dds_qos_t* qos) {
  std::vector<std::string> out;
  uint32_t n = 0;
  char** names = nullptr;
  if (qos == nullptr || !dds_qget_partition(qos, &n, &names)) return out;
  for (uint32_t i = 0; i < n; ++i) {
    out.emplace_back(names[i]);
    dds_free(names[i]);
  }
  dds_free(static_cast<void*>(names));
  return out;
}

std::optional<Duration> lease_of(const dds_qos_t* qos) {
  dds_liveliness_kind_t kind{};
  dds_duration_t lease = DDS_INFINITY;
  if (qos == nullptr || !dds_qget_liveliness(qos, &kind, &lease)) return std::nullopt;
  return finite(lease);
}

std::optional<Duration> deadline_of(const dds_qos_t* qos) {
  dds_duration_t d = DDS_INFINITY;
  if (qos == nullptr || !dds_qget_deadline(qos, &d)) return std::nullopt;
  return finite(d);
}

bool is_pattern(const std::string& name) { return name.find_first_of("*?") != std::string::npos; }

bool names_meet(const std::string& a, const std::string& b) {
  if (a == b) return true;
  const bool pa = is_pattern(a);
  const bool pb = is_pattern(b);
  if (pa == pb) return false;  // two names, or two patterns: only equal ones meet
  return pa ? fnmatch(a.c_str(), b.c_str(), 0) == 0 : fnmatch(b.c_str(), a.c_str(), 0) == 0;
}

std::vector<dds_entity_t> children_of(dds_entity_t e) {
  std::vector<dds_entity_t> out(64);
  for (;;) {
    const dds_return_t n = dds_get_children(e, out.data(), out.size());
    if (n < 0) return {};
    if (static_cast<std::size_t>(n) <= out.size()) {
      out.resize(static_cast<std::size_t>(n));
      return out;
    }
    out.resize(static_cast<std::size_t>(n));
  }
}

std::string topic_name_of(dds_entity_t endpoint) {
  const dds_entity_t topic = dds_get_topic(endpoint);
  if (topic < 0) return {};
  char name[256] = {};
  if (dds_get_name(topic, name, sizeof name) < 0) return {};
  return name;
}

}  // namespace

std::string to_string(const Guid& guid) {
  std::string s;
  for (std::size_t i = 0; i < guid.size(); ++i) {
    s += fmt::format("{}{:02x}", i > 0 && i % 4 == 0 ? ":" : "", guid[i]);
  }
  return s;
}

TypeInfo::TypeInfo(dds_entity_t topic) {
  if (dds_get_typeinfo(topic, &info_) < 0) info_ = nullptr;
}

TypeInfo::~TypeInfo() {
  if (info_ != nullptr) (void)dds_free_typeinfo(info_);
}

std::optional<bool> TypeInfo::same_as(const dds_builtintopic_endpoint_t& endpoint) const {
  const dds_typeinfo_t* theirs = nullptr;
  if (info_ == nullptr ||
      dds_builtintopic_get_endpoint_type_info(const_cast<dds_builtintopic_endpoint_t*>(&endpoint),
                                              &theirs) < 0 ||
      theirs == nullptr) {
    return std::nullopt;
  }
  return ddsi_typeinfo_equal(info_, theirs, DDSI_TYPE_INCLUDE_DEPS);
}

DiscoveredEndpoints::DiscoveredEndpoints(const Participant& participant)
    : publications_(check(dds_create_reader(participant.handle(), DDS_BUILTIN_TOPIC_DCPSPUBLICATION,
                                            nullptr, nullptr),
                          "creating a reader of the DCPSPublication built-in topic")),
      subscriptions_(check(dds_create_reader(participant.handle(),
                                             DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr),
                           "creating a reader of the DCPSSubscription built-in topic")) {}

DiscoveredEndpoint DiscoveredEndpoints::endpoint_of(const dds_builtintopic_endpoint_t& e,
                                                    const dds_sample_info_t& info, bool writer) {
  DiscoveredEndpoint d;
  d.guid = guid_of(e.key);
  d.writer = writer;
  d.alive = info.instance_state == DDS_IST_ALIVE && info.valid_data;
  if (!d.alive) return d;
  d.participant = guid_of(e.participant_key);
  if (e.topic_name != nullptr) d.topic = e.topic_name;
  if (e.type_name != nullptr) d.type_name = e.type_name;
  d.partitions = partitions_of(e.qos);
  d.lease = lease_of(e.qos);
  d.deadline = deadline_of(e.qos);
  return d;
}

std::vector<LocalEndpoint> local_endpoints(const Participant& participant) {
  std::vector<LocalEndpoint> out;
  for (const dds_entity_t parent : children_of(participant.handle())) {
    // Publishers and subscribers have the readers and writers; a topic has
    // no children.
    std::vector<std::string> partitions;
    dds_qos_t* pqos = dds_create_qos();
    if (dds_get_qos(parent, pqos) == DDS_RETCODE_OK) partitions = partitions_of(pqos);
    dds_delete_qos(pqos);
    for (const dds_entity_t e : children_of(parent)) {
      LocalEndpoint l;
      l.handle = e;
      l.writer = dds_get_publisher(e) > 0;
      if (!l.writer && dds_get_subscriber(e) <= 0) continue;  // a condition, say
      l.topic = topic_name_of(e);
      if (l.topic.empty() || l.topic.starts_with("DCPS")) continue;
      l.partitions = partitions;
      dds_qos_t* qos = dds_create_qos();
      if (dds_get_qos(e, qos) == DDS_RETCODE_OK) {
        l.deadline = deadline_of(qos);
        l.lease = lease_of(qos);
      }
      dds_delete_qos(qos);
      std::vector<dds_instance_handle_t> handles(64);
      dds_return_t n = 0;
      for (;;) {
        n = l.writer ? dds_get_matched_subscriptions(e, handles.data(), handles.size())
                     : dds_get_matched_publications(e, handles.data(), handles.size());
        if (n <= static_cast<dds_return_t>(handles.size())) break;
        handles.resize(static_cast<std::size_t>(n));  // more matched than room: again
      }
      for (dds_return_t i = 0; i < n; ++i) {
        dds_builtintopic_endpoint_t* m =
            l.writer ? dds_get_matched_subscription_data(e, handles[static_cast<std::size_t>(i)])
                     : dds_get_matched_publication_data(e, handles[static_cast<std::size_t>(i)]);
        if (m == nullptr) continue;
        l.matched.push_back(guid_of(m->key));
        dds_builtintopic_free_endpoint(m);
      }
      out.push_back(std::move(l));
    }
  }
  return out;
}

bool partitions_meet(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  static const std::vector<std::string> kDefault{""};
  const auto& pa = a.empty() ? kDefault : a;
  const auto& pb = b.empty() ? kDefault : b;
  return std::any_of(pa.begin(), pa.end(), [&](const std::string& x) {
    return std::any_of(pb.begin(), pb.end(),
                       [&](const std::string& y) { return names_meet(x, y); });
  });
}

}  // namespace dnbridge::dds
