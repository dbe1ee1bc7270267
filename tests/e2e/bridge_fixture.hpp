#pragma once
// The bridge end to end: the dnbridge daemon of `dnbridge-sim --simulate` running
// in this process (Daemon on the embedded default rack: eight simulated CDN127s
// on port "A"), and a supervisor, a DDS participant of its own that knows the
// bridge only through the topics, on loopback (tests/dds/loopback_environment.cpp:
// one domain and discovery tag per process). The simulated devices are reached
// on their port's thread (PortLoop::post), as a hand on the hardware would.
//
// Every wait is for an event, bounded: a waitset on the supervisor's readers,
// or a port-thread probe with a timeout. Nothing sleeps.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <ostream>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/daemon.hpp"
#include "adapters/daemon/simulated_backends.hpp"
#include "adapters/dds/fields.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/sim/world/sim_backend.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"
#include "dds/dds_fixture.hpp"

namespace dnbridge::profiles::cdn127 {
// What a simulated device drives, as test failures print it.
inline void PrintTo(const PumpOutputs& o, std::ostream* os) {
  *os << "{pump_on " << o.pump_on << ", n2_ballast_on " << o.n2_ballast_on << ", analog "
      << o.analog_out_raw << "}";
}
}  // namespace dnbridge::profiles::cdn127

namespace dnbridge::e2e {

using dds::testing::test_domain;
using SteadyClock = std::chrono::steady_clock;

// Long enough never to be reached when things work; bounds a failure.
inline constexpr Duration kEventTimeout = seconds(5);
inline constexpr unsigned kPumps = 8;  // the embedded default rack
inline constexpr const char* kRack = "sim-rack";
inline constexpr const char* kPort = "A";

// The wall clock DDS source timestamps are on.
inline dds::Timestamp wall_now() {
  return std::chrono::time_point_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now());
}

inline double ms_since(SteadyClock::time_point t0) {
  return std::chrono::duration<double, std::milli>(SteadyClock::now() - t0).count();
}

// A measured time, printed so that the test log shows it.
inline void report(const char* what, double ms) {
  std::printf("[ measured ] %s: %.1f ms\n", what, ms);
  ::testing::Test::RecordProperty(what, std::to_string(ms));
}

// Keeps what the bridge logs, for the tests that check it reported something.
class CapturingLog final : public LogSink {
 public:
  struct Line {
    LogLevel level;
    std::string component;
    std::string message;
  };
  bool enabled(LogLevel level) const noexcept override { return level >= LogLevel::kInfo; }
  void write(LogLevel level, std::string_view component, std::string_view message) override {
    std::lock_guard lock(mutex_);
    lines_.push_back({level, std::string(component), std::string(message)});
  }
  // Whether a line at `level` contains `text`.
  bool contains(LogLevel level, std::string_view text) const { return count(level, text) > 0; }
  // How many lines at `level` contain `text`.
  std::size_t count(LogLevel level, std::string_view text) const {
    std::lock_guard lock(mutex_);
    std::size_t n = 0;
    for (const auto& l : lines_) {
      if (l.level == level && l.message.find(text) != std::string::npos) ++n;
    }
    return n;
  }
  void dump() const {
    std::lock_guard lock(mutex_);
    for (const auto& l : lines_) {
      std::fprintf(stderr, "  %s %s: %s\n", std::string(to_string(l.level)).c_str(),
                   l.component.c_str(), l.message.c_str());
    }
  }

 private:
  mutable std::mutex mutex_;
  std::vector<Line> lines_;
};

template <class T>
struct Received {
  dds::Sample<T> sample;
  dds::Timestamp at;  // wall clock when the supervisor took it
};

// A supervisor's reader that keeps every sample it took, in order.
template <class T>
class Subscription {
 public:
  Subscription(const dds::Participant& participant, const dds::Topic<T>& topic, const dds::Qos& qos)
      : participant_(participant),
        reader_(participant, topic, qos),
        fresh_(reader_, DDS_NOT_READ_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ANY_INSTANCE_STATE),
        waitset_(participant) {
    waitset_.attach(fresh_, 1);
  }

  // Takes what arrives until `done` holds (true) or `timeout` passes (false).
  // `done` is asked after every batch and at least every `slice`, so that it
  // may act in between (a supervisor writing its command again).
  bool until(const std::function<bool()>& done, Duration timeout = kEventTimeout,
             Duration slice = milliseconds(100)) {
    const auto deadline = SteadyClock::now() + timeout;
    for (;;) {
      take_all();
      if (done()) return true;
      const auto now = SteadyClock::now();
      if (now >= deadline) return false;
      (void)waitset_.wait(std::min<Duration>(slice, deadline - now));
    }
  }

  void take_all() {
    for (;;) {
      auto taken = reader_.take();
      if (!taken.ok() || taken->empty()) return;
      const auto at = wall_now();
      for (auto& s : *taken) history_.push_back(Received<T>{std::move(s), at});
    }
  }

  // The last sample with data that `match` accepts; nullptr when none. Valid
  // until the next take.
  template <class Match>
  const T* latest(Match match) const {
    for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
      if (it->sample.valid_data() && match(it->sample.data())) return &it->sample.data();
    }
    return nullptr;
  }

  // The samples with data that `match` accepts, of those taken from
  // history()[first] on, in order. Valid until the next take.
  template <class Match>
  std::vector<const T*> since(std::size_t first, Match match) const {
    std::vector<const T*> found;
    for (std::size_t i = first; i < history_.size(); ++i) {
      const auto& sample = history_[i].sample;
      if (sample.valid_data() && match(sample.data())) found.push_back(&sample.data());
    }
    return found;
  }

  // Waits (bounded) until the reader is matched with `count` writers.
  bool matched(std::uint32_t count, Duration timeout = kEventTimeout) {
    if (!reader_.set_status_mask(DDS_SUBSCRIPTION_MATCHED_STATUS).ok()) return false;
    const auto deadline = SteadyClock::now() + timeout;
    for (;;) {
      auto m = reader_.subscription_matched();
      if (m.ok() && m->current_count == count) return true;
      const auto now = SteadyClock::now();
      if (now >= deadline) return false;
      (void)dds::testing::wait_for(participant_, reader_, deadline - now);
    }
  }

  const std::vector<Received<T>>& history() const { return history_; }
  const dds::Reader<T>& reader() const { return reader_; }

 private:
  const dds::Participant& participant_;
  dds::Reader<T> reader_;
  dds::ReadCondition fresh_;
  dds::WaitSet waitset_;
  std::vector<Received<T>> history_;
};

// A supervisor process that commands nodes through command topic T (one
// per profile: PumpCommand, DeviceCommand): a participant of its own.
template <class T>
class TestCommander {
 public:
  TestCommander(const char* issuer, std::int32_t strength)
      : issuer_(issuer),
        participant_(test_domain(), issuer),
        topic_(participant_),
        writer_(participant_, topic_,
                dds::command_writer_qos(dds::rack_partitions(kRack), strength, seconds(1))) {}

  // Node `mac`'s command, its outputs set by `fill(T&)`, stamped `ahead` of
  // this host's clock (a commander whose clock is wrong) when not zero.
  template <class Fill>
  bool write(unsigned mac, Fill fill, Duration ahead = Duration::zero()) {
    dds::Owned<T> c;
    dds::set_string(c->rack, kRack);
    dds::set_string(c->port, kPort);
    c->mac = static_cast<std::uint8_t>(mac);
    dds::set_string(c->issuer, issuer_);
    fill(*c);
    if (ahead != Duration::zero()) return writer_.write(*c, dds::dds_now() + ahead).ok();
    return writer_.write(*c).ok();
  }
  // Until the bridge has matched this commander.
  bool matched() { return dds::testing::until_matched(participant_, writer_); }
  bool acked() { return writer_.wait_for_acks(kEventTimeout).ok(); }

 private:
  std::string issuer_;
  dds::Participant participant_;
  dds::Topic<T> topic_;
  dds::Writer<T> writer_;
};

// The entity name of the participant whose writer `reader` is matched with,
// as discovery carries it; empty when not found in time.
inline std::string writer_participant_name(const dds::Participant& participant,
                                           const dds::Entity& reader) {
  dds_instance_handle_t writers[4];
  if (dds_get_matched_publications(reader.handle(), writers, 4) != 1) return {};
  dds_builtintopic_endpoint_t* writer =
      dds_get_matched_publication_data(reader.handle(), writers[0]);
  if (writer == nullptr) return {};
  const dds_guid_t key = writer->participant_key;
  dds_builtintopic_free_endpoint(writer);

  dds::Entity participants(
      dds_create_reader(participant.handle(), DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, nullptr, nullptr));
  // Woken by participants not seen yet; each pass reads them all.
  dds::ReadCondition fresh(participants,
                           DDS_NOT_READ_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ANY_INSTANCE_STATE);
  std::string name;
  while (name.empty() && dds::testing::wait_for(participant, fresh, kEventTimeout)) {
    void* samples[16] = {};
    dds_sample_info_t infos[16];
    const dds_return_t got = dds_read(participants.handle(), samples, infos, 16, 16);
    if (got < 0) return {};
    for (dds_return_t i = 0; i < got; ++i) {
      const auto* p = static_cast<const dds_builtintopic_participant_t*>(samples[i]);
      char* entity_name = nullptr;
      if (infos[i].valid_data && std::memcmp(&p->key, &key, sizeof key) == 0 &&
          dds_qget_entity_name(p->qos, &entity_name) && entity_name != nullptr) {
        name = entity_name;
        dds_free(entity_name);
      }
    }
    (void)dds_return_loan(participants.handle(), samples, got);
  }
  return name;
}

inline auto pump_mac(unsigned mac) {
  return [mac](const auto& s) { return s.mac == mac; };
}

// Runs `fn` with a port's simulated backend on the port's thread and returns
// what it returns. Throws (a test failure) if the thread does not get to it
// in time.
template <class F>
auto on_sim_port(daemon::Daemon& bridge, std::string_view port, F fn) {
  using R = std::invoke_result_t<F&, sim::SimBackend&>;
  auto done = std::make_shared<std::promise<R>>();
  auto result = done->get_future();
  bridge.port(port)->post([done, fn](port::CanBackend& backend) mutable {
    auto& sim = static_cast<sim::SimBackend&>(backend);
    if constexpr (std::is_void_v<R>) {
      fn(sim);
      done->set_value();
    } else {
      done->set_value(fn(sim));
    }
  });
  if (result.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
    throw std::runtime_error("the port's thread did not run the probe");
  }
  return result.get();
}

// The supervisor's side of the six topics, and the bridge it talks to.
class BridgeTest : public ::testing::Test {
 protected:
  // What `dnbridge-sim --simulate` runs, on this process's domain.
  static daemon::DaemonConfig rack_config() {
    auto c = daemon::embedded_default_config();
    c.domain_id = static_cast<std::uint32_t>(test_domain());
    return c;
  }

  void TearDown() override {
    if (HasFailure()) {
      std::fprintf(stderr, "bridge log:\n");
      log_.dump();
    }
  }

  // Builds the bridge (not started) and waits until the supervisor and the
  // bridge have discovered each other on every topic.
  void make_bridge(daemon::DaemonConfig config = rack_config(), daemon::ReloadSource reload = {}) {
    created_wall_ = wall_now();
    bridge_ = std::make_unique<daemon::Daemon>(
        std::move(config), log_, daemon::simulated_backend_factory(log_), std::move(reload));
    ASSERT_TRUE(pumps_.matched(1));
    ASSERT_TRUE(nodes_.matched(1));
    ASSERT_TRUE(ports_.matched(1));
    ASSERT_TRUE(replies_.matched(1));
    ASSERT_TRUE(writer_matched(requests_));
  }

  void start_bridge() {
    started_ = SteadyClock::now();
    started_wall_ = wall_now();
    bridge_->start();
  }

  // Every pump's PumpState says online, with inputs from a poll response.
  bool all_online() const {
    for (unsigned mac = 1; mac <= kPumps; ++mac) {
      const auto* s = pumps_.latest(pump_mac(mac));
      if (!s || !s->online || !s->inputs_valid) return false;
    }
    return true;
  }

  // Built, started, and every pump online as the supervisor sees it.
  void start_online(daemon::DaemonConfig config = rack_config(), daemon::ReloadSource reload = {}) {
    ASSERT_NO_FATAL_FAILURE(make_bridge(std::move(config), std::move(reload)));
    start_bridge();
    ASSERT_TRUE(pumps_.until([&] { return all_online(); }, seconds(10)));
  }

  template <class T>
  bool writer_matched(const dds::Writer<T>& writer, std::uint32_t count = 1) {
    return dds::testing::until_matched(supervisor_, writer, count);
  }

  // Runs `fn` with the port's simulated backend on the port's thread
  // (on_sim_port above).
  template <class F>
  auto on_port(F fn) {
    return on_sim_port(*bridge_, kPort, std::move(fn));
  }

  static sim::SimSlave& slave(sim::SimBackend& backend, unsigned mac) {
    return backend.device(*devicenet::MacId::from(mac));
  }

  CapturingLog log_;
  dds::Participant supervisor_{test_domain(), "e2e supervisor"};
  dds::Topic<dnbridge_PumpState> pump_topic_{supervisor_};
  dds::Topic<dnbridge_NodeStatus> node_topic_{supervisor_};
  dds::Topic<dnbridge_PortStatus> port_topic_{supervisor_};
  dds::Topic<dnbridge_ExplicitRequest> request_topic_{supervisor_};
  dds::Topic<dnbridge_ExplicitReply> reply_topic_{supervisor_};
  Subscription<dnbridge_PumpState> pumps_{supervisor_, pump_topic_, dds::state_reader_qos()};
  Subscription<dnbridge_NodeStatus> nodes_{supervisor_, node_topic_, dds::state_reader_qos()};
  Subscription<dnbridge_PortStatus> ports_{supervisor_, port_topic_, dds::state_reader_qos()};
  Subscription<dnbridge_ExplicitReply> replies_{supervisor_, reply_topic_,
                                                dds::reply_reader_qos(dds::rack_partitions(kRack))};
  dds::Writer<dnbridge_ExplicitRequest> requests_{
      supervisor_, request_topic_, dds::request_writer_qos(dds::rack_partitions(kRack))};
  const std::string requester_ = "e2e@" + std::to_string(getpid());

  dds::Timestamp created_wall_{};  // before the bridge was built
  dds::Timestamp started_wall_{};
  SteadyClock::time_point started_{};
  // Last: stopped and destroyed before the supervisor's entities.
  std::unique_ptr<daemon::Daemon> bridge_;
};

// --- explicit messaging ------------------------------------------------------

struct Request {
  std::uint32_t txid = 0;
  std::uint8_t command = 1;  // COMMAND_EXECUTE
  std::string port = kPort;
  std::uint8_t mac = 1;
  std::uint8_t service = 0x0E;  // Get_Attribute_Single
  std::uint16_t class_id = 1;   // Identity
  std::uint16_t instance_id = 1;
  std::optional<std::uint8_t> attribute = 1;
  std::vector<std::uint8_t> data;
  std::string rack = kRack;
};

class ExplicitTest : public BridgeTest {
 protected:
  void send(const Request& r) {
    dds::Owned<dnbridge_ExplicitRequest> s;
    dds::set_string(s->requester, requester_);
    s->txid = r.txid;
    s->command = r.command;
    dds::set_string(s->rack, r.rack);
    dds::set_string(s->port, r.port);
    s->mac = r.mac;
    s->service = r.service;
    s->class_id = r.class_id;
    s->instance_id = r.instance_id;
    s->has_attribute = r.attribute.has_value();
    s->attribute_id = r.attribute.value_or(0);
    dds::set_octets(s->data, r.data);
    ASSERT_TRUE(requests_.write(*s).ok());
  }

  std::size_t reply_count(std::uint32_t txid) const {
    std::size_t n = 0;
    for (const auto& r : replies_.history()) {
      if (r.sample.valid_data() && r.sample->txid == txid &&
          dds::view(r.sample->requester) == requester_) {
        ++n;
      }
    }
    return n;
  }

  // The `nth` reply (from 0) of `txid`, waiting for it; nullopt on timeout.
  struct Reply {
    std::uint8_t status = 0;
    std::uint8_t general_status = 0;
    std::uint8_t additional_status = 0;
    std::vector<std::uint8_t> data;
    std::string message;
  };
  std::optional<Reply> reply(std::uint32_t txid, std::size_t nth = 0,
                             Duration timeout = kEventTimeout) {
    if (!replies_.until([&] { return reply_count(txid) > nth; }, timeout)) return std::nullopt;
    for (const auto& r : replies_.history()) {
      if (!r.sample.valid_data() || r.sample->txid != txid ||
          dds::view(r.sample->requester) != requester_) {
        continue;
      }
      if (nth-- == 0) {
        const auto& s = r.sample.data();
        const auto data = dds::view(s.data);
        return Reply{s.status, s.general_status, s.additional_status,
                     std::vector<std::uint8_t>(data.begin(), data.end()),
                     std::string(dds::view(s.message))};
      }
    }
    return std::nullopt;
  }
};

}  // namespace dnbridge::e2e
