#pragma once
// The DDS face of the ports: writes PumpState, NodeStatus, PortStatus and
// ExplicitReply samples. Called from every port's thread, it fills each
// sample there. State samples (and their instances' disposal and
// unregistration) are written there too: their writers are keep-last, and
// Cyclone DDS never holds a keep-last write back for readers that have not
// acknowledged (0.10.2 gives such a writer no history watermarks:
// src/core/ddsi/src/ddsi_endpoint.c, "aggressive keep last"), so a reader
// that stops acknowledging delays no poll (tests/e2e/careless_client_test.cpp
// shows it). Their max blocking time is zero besides: should a write still
// have to wait for room, it fails at once, is logged and counted
// (state_write_failures), and the next sample of the instance follows. What
// a write can still wait for is short and not bounded by DDS: the writer's
// lock, shared with the other ports and Cyclone's acknowledgment handling,
// and the socket's send buffer. Replies are handed to an outbox
// (adapters/daemon/outbox.hpp) and written on its thread, at most
// kReplyBacklog waiting. Each sample carries the monotonic event time mapped
// to the wall clock as its source timestamp.
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/daemon/outbox.hpp"
#include "adapters/daemon/profile_topics.hpp"
#include "adapters/daemon/reload.hpp"
#include "adapters/daemon/unless_denied.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/time.hpp"
#include "adapters/dds/topic.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/port/port_publisher.hpp"
#include "bridge/common/log.hpp"

namespace dnbridge::daemon {

// Maps the steady clock the ports run on to the wall clock DDS stamps with.
class WallClock {
 public:
  WallClock();
  dds::Timestamp to_wall(TimePoint monotonic) const;

 private:
  std::chrono::nanoseconds offset_;
};

// A request/reply service of the bridge besides the pumps' topics (the bus
// scan, reload): its two topics and the reply writer.
template <class Request, class Reply>
struct Service {
  Service(const dds::Participant& participant, const dds::Qos& reply_qos)
      : requests(participant), replies(participant), writer(participant, replies, reply_qos) {}
  dds::Topic<Request> requests;
  dds::Topic<Reply> replies;
  dds::Writer<Reply> writer;
};

class DdsPublisher final : public port::PortPublisher {
 public:
  // `state_deadline`: the deadline offered on the state topics (each
  // instance is written at least that often while its port runs).
  // `profiles`: the state topic of each (profile_topics.hpp).
  DdsPublisher(const dds::Participant& participant, std::string rack, Duration state_deadline,
               Logger log, std::span<const ProfileTopics> profiles = bridge_profiles());
  ~DdsPublisher() override;

  void node_state(const std::string& port, const rack::NodeView& node,
                  TimePoint source_time) override;
  void node_status(const std::string& port, const rack::NodeView& node,
                   const port::NodeStatusView& status, TimePoint source_time) override;
  void port_status(const port::PortStatusView& status, TimePoint source_time) override;
  void explicit_reply(const std::string& port, const rack::ExplicitAnswer& answer) override;
  void bus_scan_reply(const std::string& port, const port::BusScanAnswer& answer) override;
  void port_stopped(const std::string& port) override;
  void node_removed(const std::string& port, devicenet::MacId mac) override;
  // The answer to a ReloadRequest (any thread).
  void reload_reply(const ReloadCall& call, const ReloadReport& report);

  // Waits (at most `timeout`) until what was handed over is written and every
  // reader has acknowledged it: the last samples of a shutdown reach their
  // readers.
  void flush(Duration timeout);

  // Replies not written (the outbox full, or the write failed) for `port`.
  std::uint64_t replies_undelivered(const std::string& port) const;
  // The reply outbox's counters.
  Outbox::Counters reply_queue() const { return reply_out_.counters(); }
  // State samples, disposals and unregistrations whose write failed.
  std::uint64_t state_write_failures() const {
    return state_write_failures_.load(std::memory_order_relaxed);
  }
  // The rack's figures that every PortStatus carries (any thread).
  void set_max_commander_lease(Duration lease) {
    max_commander_lease_ms_ =
        static_cast<std::uint32_t>(std::chrono::duration_cast<milliseconds>(lease).count());
  }
  void set_endpoint_counts(std::uint32_t commanders_refused, std::uint32_t endpoints_unmatched) {
    commanders_refused_ = commanders_refused;
    endpoints_unmatched_ = endpoints_unmatched;
  }
  // Replies handed over at most this many at a time; more are undelivered.
  static constexpr std::size_t kReplyBacklog = 1024;

  const dds::Topic<dnbridge_ExplicitRequest>& request_topic() const { return request_topic_; }
  // Null when DDS Security does not grant the service (unless_denied).
  const dds::Topic<dnbridge_BusScanRequest>* scan_request_topic() const {
    return scan_ ? &scan_->requests : nullptr;
  }
  const dds::Topic<dnbridge_ReloadRequest>* reload_request_topic() const {
    return reload_ ? &reload_->requests : nullptr;
  }

 private:
  // Logs a failed write (rate-limited); true when it succeeded.
  bool check(Status s, const char* what);
  // The same for a state topic's write, disposal or unregistration, counted.
  void check_state(Status s, const char* what);
  // The state topic of `profile`; null for a profile it does not know.
  StateTopic* state_topic(std::string_view profile) const;
  // The state topic a node's samples were written on, besides NodeStatus.
  void note_written(const std::string& port, std::uint8_t mac, StateTopic& topic);
  // A node's state instance and NodeStatus unregistered, after being
  // disposed when `dispose`.
  void release_node(const std::string& port, std::uint8_t mac, StateTopic& topic, bool dispose);

  std::string rack_;
  Logger log_;
  std::atomic<std::uint32_t> max_commander_lease_ms_{0};
  std::atomic<std::uint32_t> commanders_refused_{0};
  std::atomic<std::uint32_t> endpoints_unmatched_{0};
  // The rack's partition, where its replies go (dds::rack_partition).
  std::vector<std::string> partition_;
  WallClock clock_;
  dds::Topic<dnbridge_NodeStatus> node_topic_;
  dds::Topic<dnbridge_PortStatus> port_topic_;
  dds::Topic<dnbridge_ExplicitRequest> request_topic_;
  dds::Topic<dnbridge_ExplicitReply> reply_topic_;
  std::vector<std::unique_ptr<StateTopic>> state_topics_;  // one per profile
  dds::Writer<dnbridge_NodeStatus> node_writer_;
  dds::Writer<dnbridge_PortStatus> port_writer_;
  dds::Writer<dnbridge_ExplicitReply> reply_writer_;
  std::optional<Service<dnbridge_BusScanRequest, dnbridge_BusScanReply>> scan_;
  std::optional<Service<dnbridge_ReloadRequest, dnbridge_ReloadReply>> reload_;

  void undelivered(const std::string& port);

  mutable std::mutex mutex_;
  std::map<std::string, std::map<std::uint8_t, StateTopic*>> written_;  // per port, by MAC
  std::map<std::string, std::uint64_t> undelivered_;                    // per port
  std::mutex log_mutex_;
  RateLimitedLog error_limit_;
  std::atomic<std::uint64_t> state_write_failures_{0};
  // Last: its thread ends, after writing what waits, before the writers go.
  Outbox reply_out_;
};

}  // namespace dnbridge::daemon
