#include "adapters/dnbctl/client.hpp"

#include <pwd.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <utility>

#include "adapters/dds/fields.hpp"
#include "adapters/version/version.hpp"

namespace dnbridge::dnbctl {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;

extern "C" void on_interrupt(int) { g_interrupted = 1; }

// Waits are cut into slices this long so that an interrupt is noticed.
constexpr Duration kSlice = milliseconds(100);

enum Token : dds::WaitSet::Token { kPumpData = 1, kNodeData = 2, kPortData = 3, kDeviceData = 4 };

NodeKey node_key(std::string_view rack, std::string_view port, std::uint8_t mac) {
  return NodeKey{std::string(rack), std::string(port), mac};
}

// Moves each taken sample into its instance's slot: the newest valid
// sample replaces the data; an invalid one only says the writer left (or
// came back). `on_update` sees every change.
template <class T, class K, class KeyOf, class OnUpdate>
void absorb(std::vector<dds::Sample<T>>& samples, std::map<K, Known<T>>& cache, KeyOf key_of,
            OnUpdate on_update) {
  for (auto& s : samples) {
    K key = key_of(s.data());
    const bool alive = s.info().instance_state() == dds::InstanceState::kAlive;
    if (!s.valid_data()) {
      auto it = cache.find(key);
      if (it != cache.end() && it->second.alive != alive) {
        it->second.alive = alive;
        on_update(key, it->second);
      }
      continue;
    }
    Known<T>& k = cache[key];
    std::swap(*k.data, s.data());  // the sample frees what was cached before
    k.alive = alive;
    ++k.samples;
    on_update(key, k);
  }
}

}  // namespace

void install_interrupt_handlers() {
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool interrupted() noexcept { return g_interrupted != 0; }

Client::Client(std::uint32_t domain, const std::string& name, const dds::Properties& properties)
    : participant_(static_cast<dds_domainid_t>(domain), dds::Participant::ClientName{name},
                   properties, dds::host_user_data(version::number())),
      pump_topic_(participant_),
      node_topic_(participant_),
      port_topic_(participant_),
      pump_reader_(participant_, pump_topic_, dds::state_reader_qos()),
      node_reader_(participant_, node_topic_, dds::state_reader_qos()),
      port_reader_(participant_, port_topic_, dds::state_reader_qos()),
      pump_data_(pump_reader_, DDS_ANY_STATE),
      node_data_(node_reader_, DDS_ANY_STATE),
      port_data_(port_reader_, DDS_ANY_STATE),
      waitset_(participant_) {
  waitset_.attach(pump_data_, kPumpData);
  try {
    devices_in_.emplace(participant_);
    waitset_.attach(devices_in_->data, kDeviceData);
  } catch (const dds::Error& e) {
    if (e.code() != DDS_RETCODE_NOT_ALLOWED_BY_SECURITY) throw;
  }
  waitset_.attach(node_data_, kNodeData);
  waitset_.attach(port_data_, kPortData);
}

void Client::refresh(
    const std::function<void(const NodeKey&, const Known<dnbridge_PumpState>&)>& on_pump) {
  // Take until empty: a burst of transient-local history can exceed one take.
  for (;;) {
    auto samples = pump_reader_.take();
    if (!samples || samples->empty()) break;
    absorb(
        *samples, pumps_,
        [](const dnbridge_PumpState& s) {
          return node_key(dds::view(s.rack), dds::view(s.port), s.mac);
        },
        [&](const NodeKey& key, const Known<dnbridge_PumpState>& k) {
          if (on_pump) on_pump(key, k);
        });
  }
  while (devices_in_) {
    auto samples = devices_in_->reader.take();
    if (!samples || samples->empty()) break;
    absorb(
        *samples, devices_,
        [](const dnbridge_DeviceState& s) {
          return node_key(dds::view(s.rack), dds::view(s.port), s.mac);
        },
        [](const NodeKey&, const Known<dnbridge_DeviceState>&) {});
  }
  for (;;) {
    auto samples = node_reader_.take();
    if (!samples || samples->empty()) break;
    absorb(
        *samples, nodes_,
        [](const dnbridge_NodeStatus& s) {
          return node_key(dds::view(s.rack), dds::view(s.port), s.mac);
        },
        [](const NodeKey&, const Known<dnbridge_NodeStatus>&) {});
  }
  for (;;) {
    auto samples = port_reader_.take();
    if (!samples || samples->empty()) break;
    absorb(
        *samples, ports_,
        [](const dnbridge_PortStatus& s) {
          return PortKey{std::string(dds::view(s.rack)), std::string(dds::view(s.port))};
        },
        [](const PortKey&, const Known<dnbridge_PortStatus>&) {});
  }
}

void Client::wait(Duration timeout) {
  if (interrupted()) return;
  (void)waitset_.wait(std::min(timeout, kSlice));
}

bool Client::wait_until(Deadline deadline, const std::function<bool()>& done) {
  for (;;) {
    refresh();
    if (done()) return true;
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline || interrupted()) return false;
    wait(std::chrono::duration_cast<Duration>(deadline - now));
  }
}

const Known<dnbridge_PumpState>* Client::pump(const NodeKey& key) const {
  auto it = pumps_.find(key);
  return it == pumps_.end() ? nullptr : &it->second;
}

Client::DevicesIn::DevicesIn(const dds::Participant& participant)
    : topic(participant),
      reader(participant, topic, dds::state_reader_qos()),
      data(reader, DDS_ANY_STATE) {}

const Known<dnbridge_DeviceState>* Client::device(const NodeKey& key) const {
  auto it = devices_.find(key);
  return it == devices_.end() ? nullptr : &it->second;
}

const Known<dnbridge_NodeStatus>* Client::node(const NodeKey& key) const {
  auto it = nodes_.find(key);
  return it == nodes_.end() ? nullptr : &it->second;
}

std::string host_name() {
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) != 0) return "localhost";
  return buf;
}

std::string user_at_host() {
  std::string user;
  if (const char* u = std::getenv("USER"); u != nullptr && *u != '\0') {
    user = u;
  } else if (const passwd* pw = getpwuid(geteuid()); pw != nullptr) {
    user = pw->pw_name;
  } else {
    user = std::to_string(geteuid());
  }
  return user + "@" + host_name();
}

}  // namespace dnbridge::dnbctl
