// dnbridge_plant_host: a host of the plant network in the multi-host test
// (multihost_test.cpp runs it in a network namespace of its own): one DDS
// participant, with the [security] table of --security FILE or without any,
// that watches every rack's PumpState and commands pumps when told to.
//
//   dnbridge_plant_host DOMAIN EXPECTED FRESH_MS [--security FILE]
//
// It talks with the test a line at a time on stdin and stdout (a socket,
// ChildOptions::control). What it prints by itself:
//
//   view complete T          every one of EXPECTED PumpState instances had a
//                            sample in the last FRESH_MS (T: CLOCK_MONOTONIC,
//                            ns, the time the last missing one came)
//   view incomplete T N      N of them had none for FRESH_MS (T: when the
//                            first went stale)
//   node RACK PORT MAC online=0|1 idle=0|1 pump_on=0|1 by=ISSUER reason=TEXT
//                            a pump came online or went away, its outputs
//                            changed, or it was seen first
//   node RACK PORT MAC gone  its bridge is gone (no writer left: lease expired)
//
// What it answers:
//
//   command RACK PORT MAC on|off   written RACK READERS | refused RACK WHY
//        writes PumpCommand with the documented commander QoS (strength 10,
//        dnbctl's lease) in RACK's partition; a writer per rack, made at
//        its first command (refused: DDS Security denied it); READERS is how
//        many command readers (bridges) its writer had matched when it wrote
//        (it waits up to 5 s for the first). As dnbctl does, it writes the
//        command again every second until the pump's PumpState shows it
//        applied (a sample written as soon as the writer matched can reach
//        the bridge before the bridge has discovered the writer, and be
//        dropped there), and not after that; after 30 s without, it gives
//        up and says "gave up RACK PORT MAC". (Applied is looked at when a
//        PumpState sample comes: every pump publishes at least once a
//        second.)
//   status      status instances=I samples=S
//        PumpState instances seen, valid samples of them taken.
//   show RACK PORT MAC   shown, then the node line of that pump as it is now
//                        (its outputs "none" if never seen)
//   wait-samples N       samples N, once every pump seen had N more valid
//                        PumpState samples
//
// At the end of stdin it exits 0. CYCLONEDDS_URI is the test's plant-network
// configuration.

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <exception>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "adapters/dds/fields.hpp"
#include "adapters/dnbctl/client.hpp"
#include "adapters/dnbctl/commander.hpp"
#include "adapters/security/check.hpp"
#include "adapters/security/toml_settings.hpp"
#include "support/stdin_lines.hpp"

namespace {

using namespace dnbridge;
using dnbctl::NodeKey;
using Clock = std::chrono::steady_clock;

// CLOCK_MONOTONIC in ns: one clock for every process of the machine (network
// namespaces do not change it), so the test compares these times with its own.
std::int64_t monotonic_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

void say(const std::string& line) {
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

std::string outputs_of(const dnbridge_PumpState& s) {
  std::ostringstream o;
  o << "online=" << (s.online ? 1 : 0) << " idle=" << (s.outputs_idle ? 1 : 0)
    << " pump_on=" << (s.pump_on ? 1 : 0) << " by=" << dds::view(s.commanded_by)
    << " reason=" << dds::view(s.idle_reason);
  return o.str();
}

std::string node_line(const NodeKey& key, const std::string& outputs) {
  return "node " + key.rack + " " + key.port + " " + std::to_string(key.mac) + " " + outputs;
}

class PlantHost {
 public:
  PlantHost(dds_domainid_t domain, std::size_t expected, std::chrono::milliseconds fresh,
            const dds::Properties& properties)
      : client_(static_cast<std::uint32_t>(domain), "plant host", properties),
        expected_(expected),
        fresh_(fresh) {}

  // Until the end of stdin.
  void run() {
    support::StdinLines input;
    for (;;) {
      client_.refresh();
      look();
      rewrite();
      if (samples_asked_ && every_pump_had(*samples_asked_)) {
        say("samples " + std::to_string(*samples_asked_));
        samples_asked_.reset();
      }
      check_view();
      if (!input.read(0, [this](const std::string& line) { answer(line); })) return;
      // Woken by state, or in 20 ms to look at stdin and staleness again.
      client_.wait(milliseconds(20));
    }
  }

 private:
  struct Pump {
    std::uint64_t samples = 0;
    Clock::time_point last_sample;
    std::string outputs;
  };

  // What the client took since the last look (here, or while a command
  // waited for its bridge): a pump whose sample count grew had a sample now.
  void look() {
    const auto now = Clock::now();
    for (const auto& [key, known] : client_.pumps()) {
      auto& pump = pumps_[key];
      if (!known.alive) {
        if (pump.outputs != "gone") say(node_line(key, pump.outputs = "gone"));
        continue;
      }
      if (known.samples == pump.samples) continue;
      pump.samples = known.samples;
      pump.last_sample = now;
      if (auto outputs = outputs_of(*known.data); outputs != pump.outputs) {
        pump.outputs = std::move(outputs);
        say(node_line(key, pump.outputs));
      }
      if (const auto it = unapplied_.find(key);
          it != unapplied_.end() && !known.data->outputs_idle &&
          known.data->pump_on == it->second.on && dds::view(known.data->commanded_by) == kIssuer) {
        unapplied_.erase(it);
      }
    }
  }

  // Every pump seen when wait-samples was asked had `n` more samples since.
  bool every_pump_had(std::uint64_t n) const {
    for (const auto& [k, from] : samples_from_) {
      const auto* known = client_.pump(k);
      if (!known || known->samples < from + n) return false;
    }
    return true;
  }

  std::uint64_t total_samples() const {
    std::uint64_t n = 0;
    for (const auto& [k, known] : client_.pumps()) n += known.samples;
    return n;
  }

  // A change of the view is said once, when it happens.
  void check_view() {
    const auto now = Clock::now();
    std::size_t stale = expected_ > pumps_.size() ? expected_ - pumps_.size() : 0;
    for (const auto& [key, pump] : pumps_) {
      if (now - pump.last_sample > fresh_) ++stale;
    }
    const bool complete = stale == 0;
    if (complete == complete_) return;
    complete_ = complete;
    say(complete
            ? "view complete " + std::to_string(monotonic_ns())
            : "view incomplete " + std::to_string(monotonic_ns()) + " " + std::to_string(stale));
  }

  void answer(const std::string& line) {
    std::istringstream in(line);
    std::string verb;
    in >> verb;
    if (verb == "wait-samples") {
      std::uint64_t n = 0;
      if (in >> n && n > 0) {
        samples_asked_ = n;
        samples_from_.clear();
        for (const auto& [k, known] : client_.pumps()) samples_from_[k] = known.samples;
        return;
      }
    } else if (verb == "status") {
      say("status instances=" + std::to_string(client_.pumps().size()) +
          " samples=" + std::to_string(total_samples()));
      return;
    }
    NodeKey key;
    unsigned mac = 0;
    if (in >> key.rack >> key.port >> mac && mac < 64) {
      key.mac = static_cast<std::uint8_t>(mac);
      if (verb == "command") {
        std::string onoff;
        in >> onoff;
        command(key, onoff == "on");
        return;
      }
      if (verb == "show") {
        const auto it = pumps_.find(key);
        say("shown " + node_line(key, it == pumps_.end() ? "none" : it->second.outputs));
        return;
      }
    }
    say("unknown " + line);
  }

  void command(const NodeKey& key, bool on) {
    auto& commander = commanders_[key.rack];
    if (!commander) {
      try {
        commander =
            std::make_unique<dnbctl::Commander<dnbridge_PumpCommand>>(client_, 10, key.rack);
      } catch (const dds::Error& e) {
        commanders_.erase(key.rack);
        say("refused " + key.rack + " " + e.what());
        return;
      }
    }
    // The first bridge's reader, within 5 s; any matched later is not waited for.
    (void)commander->wait_matched(client_, Clock::now() + std::chrono::seconds(5));
    if (!commander->write(key, dnbctl::Outputs{.pump_on = on}, kIssuer).ok()) {
      say("refused " + key.rack + " write failed");
      return;
    }
    say("written " + key.rack + " " + std::to_string(commander->matched()));
    unapplied_[key] = Unapplied{on, Clock::now(), Clock::now()};
  }

  // Each command not yet seen applied, written again a second after the
  // last time, for 30 s.
  void rewrite() {
    const auto now = Clock::now();
    for (auto it = unapplied_.begin(); it != unapplied_.end();) {
      if (now - it->second.first > std::chrono::seconds(30)) {
        say("gave up " + it->first.rack + " " + it->first.port + " " +
            std::to_string(it->first.mac));
        it = unapplied_.erase(it);
        continue;
      }
      auto& [key, command] = *it++;
      if (now - command.written < std::chrono::seconds(1)) continue;
      (void)commanders_[key.rack]->write(key, dnbctl::Outputs{.pump_on = command.on}, kIssuer);
      command.written = now;
    }
  }

  static constexpr const char* kIssuer = "plant host";
  struct Unapplied {
    bool on = false;
    Clock::time_point first, written;
  };

  dnbctl::Client client_;
  std::map<std::string, std::unique_ptr<dnbctl::Commander<dnbridge_PumpCommand>>> commanders_;
  std::map<NodeKey, Unapplied> unapplied_;
  std::size_t expected_;
  std::chrono::milliseconds fresh_;
  std::map<NodeKey, Pump> pumps_;
  bool complete_ = false;
  std::optional<std::uint64_t> samples_asked_;
  std::map<NodeKey, std::uint64_t> samples_from_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4 && !(argc == 6 && std::string_view(argv[4]) == "--security")) {
    std::fprintf(stderr, "usage: dnbridge_plant_host DOMAIN EXPECTED FRESH_MS [--security FILE]\n");
    return 2;
  }
  try {
    dds::Properties properties;
    if (argc == 6) {
      auto settings = security::load_file(argv[5]);
      (void)security::check(settings);
      properties = security::participant_properties(settings);
    }
    PlantHost host(static_cast<dds_domainid_t>(std::stoi(argv[1])),
                   static_cast<std::size_t>(std::stoul(argv[2])),
                   std::chrono::milliseconds(std::stol(argv[3])), properties);
    host.run();
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dnbridge_plant_host: %s\n", e.what());
    return 1;
  }
}
