#pragma once
// The DDS endpoints on the bridge's topics that the bridge does not match,
// as discovery shows them: command writers of this rack whose liveliness
// lease or deadline the rack refuses (max_commander_lease_ms,
// command_refresh_ms: DDS does not match them, and their writer sees an
// incompatible QoS), and readers and writers whose type (or QoS) differs
// from the bridge's (a reader built from another IDL matches nothing and
// says nothing on its side). Each is logged once, with the identity of its
// participant, and those present now are counted (PortStatus). On a thread
// of its own; nothing here touches the command path.
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>

#include "adapters/dds/discovered_endpoints.hpp"
#include "adapters/dds/discovered_participants.hpp"
#include "adapters/dds/waitset.hpp"
#include "bridge/common/log.hpp"

namespace dnbridge::daemon {

class EndpointWatch {
 public:
  struct Settings {
    std::string rack;
    Duration max_commander_lease;
    // The nodes with a command refresh of `ms`, in words ("port A: 3, 4"),
    // for the messages.
    std::function<std::string(std::uint32_t ms)> nodes_with_refresh;
    // Called (on the watch's thread) when a count changes.
    std::function<void(std::uint32_t commanders_refused, std::uint32_t endpoints_unmatched)>
        counted;
    // How long an endpoint may stay unmatched after its discovery before it
    // counts: matching may wait for its type to be resolved.
    Duration grace = seconds(3);
    Duration period = seconds(1);  // how often the matches are looked at again
  };
  EndpointWatch(const dds::Participant& participant, Settings settings, Logger log);
  ~EndpointWatch();
  EndpointWatch(const EndpointWatch&) = delete;
  EndpointWatch& operator=(const EndpointWatch&) = delete;

  void start();
  void stop();

  std::uint32_t commanders_refused() const { return commanders_refused_.load(); }
  std::uint32_t endpoints_unmatched() const { return endpoints_unmatched_.load(); }

 private:
  struct Remote {
    dds::DiscoveredEndpoint endpoint;
    TimePoint first_seen{};
    std::string reported;  // what was logged of it; empty: nothing
  };
  void run();
  void take(TimePoint now);
  void look(TimePoint now);
  // Why `r` is not matched by `unmatched_by` (local endpoints of its topic
  // and partitions), and whether it is a refused commander.
  std::string why_unmatched(const Remote& r, const std::vector<const dds::LocalEndpoint*>& by,
                            bool& commander) const;
  std::string who(const dds::DiscoveredEndpoint& e) const;
  // Whether `l` is one of the bridge's endpoints that counts: not a command
  // reader of a refresh that no node has now (after a reload).
  bool serves_nodes(const dds::LocalEndpoint& l) const;
  const dds::TypeInfo* type_of(std::string_view topic);
  // The type information of the topics of `locals` not known yet.
  void learn_types(const std::vector<dds::LocalEndpoint>& locals);

  const dds::Participant& participant_;
  Settings settings_;
  Logger log_;
  dds::Guid self_{};
  std::vector<std::string> rack_partition_;
  dds::DiscoveredParticipants participants_reader_;
  dds::DiscoveredEndpoints endpoints_reader_;
  dds::GuardCondition stop_;
  dds::WaitSet waitset_;
  std::thread thread_;
  std::map<dds::Guid, dds::DiscoveredParticipant> participants_;
  std::map<dds::Guid, Remote> remotes_;
  std::map<std::string, std::unique_ptr<dds::TypeInfo>, std::less<>> types_;
  std::atomic<std::uint32_t> commanders_refused_{0};
  std::atomic<std::uint32_t> endpoints_unmatched_{0};
};

}  // namespace dnbridge::daemon
