#pragma once
// A command writer (PumpCommand, DeviceCommand: one topic per profile):
// dnbctl as a supervisor of one node for as long as it runs. Exclusive
// ownership: of the live writers of a node's instance the strongest
// commands it. When this writer goes (dnbctl exits), the node passes to the
// next strongest commander or, with none left, to the bridge's no-commander
// policy (idle, or hold the last outputs).
#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topic.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/dnbctl/client.hpp"

namespace dnbridge::dnbctl {

struct Outputs {
  bool pump_on = false;
  bool n2_ballast_on = false;
  std::uint16_t analog_output_raw = 0;
  bool operator==(const Outputs&) const = default;
};

// How long the bridge waits, after dnbctl stops renewing its liveliness
// (killed, frozen), before it takes a command as gone; shorter when the
// rack's bound is (PortStatus.max_commander_lease_ms).
inline constexpr Duration kCommandLease = seconds(2);

// What the node's bridge asks of a commander: the node's command refresh
// (zero: none) and the liveliness lease to offer.
struct CommandTerms {
  Duration refresh = Duration::zero();
  Duration lease = kCommandLease;
};

// How often a command is written again while it is held: every second, and
// four times per command refresh when the node has one, so that a write
// lost or late on the network still leaves it in force.
inline Duration rewrite_period(Duration refresh) {
  return refresh > Duration::zero() ? std::min<Duration>(seconds(1), refresh / 4) : seconds(1);
}

// A device's outputs (DeviceCommand): its bytes, or its fields by name.
struct DeviceOutputs {
  std::vector<std::uint8_t> bytes;
  std::vector<std::pair<std::string, double>> fields;  // used when `bytes` is empty
};

// A command sample's outputs, one filler per command topic (each commands
// the nodes of one profile).
void fill_command(dnbridge_PumpCommand& command, const Outputs& outputs);
void fill_command(dnbridge_DeviceCommand& command, const DeviceOutputs& outputs);

// A writer of command topic T for the nodes of `rack` (in its partition:
// only its bridge gets them), offering `terms.lease`. `terms.refresh`: the
// node's command refresh, offered as the writer's deadline; the command
// must then be written again at least that often (rewrite_period).
template <class T>
class Commander {
 public:
  Commander(Client& client, std::int32_t strength, const std::string& rack,
            const CommandTerms& terms = {})
      : topic_(client.participant()),
        writer_(
            client.participant(), topic_,
            dds::command_writer_qos(
                std::vector{dds::rack_partition(rack)}, strength, terms.lease,
                terms.refresh > Duration::zero() ? std::optional(terms.refresh) : std::nullopt)) {}

  // Until a command reader (a bridge) matched; false at the deadline.
  // Commands are volatile: one written before a bridge matched is lost.
  bool wait_matched(Client& client, Deadline deadline) {
    return client.wait_until(deadline, [&] {
      auto n = writer_.matched_subscriptions();
      return n.ok() && *n > 0;
    });
  }
  // Command readers (bridges) matched now: with partitions, its rack's only.
  std::uint32_t matched() const { return writer_.matched_subscriptions().value_or(0); }

  // The node's command, its outputs as fill_command takes them for T.
  template <class Outputs>
  Status write(const NodeKey& key, const Outputs& outputs, const std::string& issuer) {
    dds::Owned<T> c;
    dds::set_string(c->rack, key.rack);
    dds::set_string(c->port, key.port);
    c->mac = key.mac;
    fill_command(*c, outputs);
    dds::set_string(c->issuer, issuer);
    return writer_.write(*c);
  }

 private:
  dds::Topic<T> topic_;
  dds::Writer<T> writer_;
};

}  // namespace dnbridge::dnbctl
