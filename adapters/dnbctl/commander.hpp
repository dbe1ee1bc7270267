#pragma once
// A PumpCommand writer: dnbctl as a supervisor of one pump for as long as it
// runs. Exclusive ownership: of the live writers of a pump's instance the
// strongest commands it. When this writer goes (dnbctl exits), the pump
// passes to the next strongest commander or, with none left, to the bridge's
// no-commander policy (idle, or hold the last outputs).
#include <cstdint>
#include <string>

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

class Commander {
 public:
  // How long the bridge waits, after dnbctl stops renewing its liveliness
  // (killed, frozen), before it takes the command as gone.
  static constexpr Duration kLease = seconds(2);

  // Commands pumps of `rack` (in its partition: only its bridge gets them).
  Commander(Client& client, std::int32_t strength, const std::string& rack);

  // Until a command reader (a bridge) matched; false at the deadline.
  // Commands are volatile: one written before a bridge matched is lost.
  bool wait_matched(Client& client, Deadline deadline);
  // Command readers (bridges) matched now: with partitions, its rack's only.
  std::uint32_t matched() const;

  Status write(const NodeKey& key, const Outputs& outputs, const std::string& issuer);

 private:
  dds::Topic<dnbridge_PumpCommand> topic_;
  dds::Writer<dnbridge_PumpCommand> writer_;
};

}  // namespace dnbridge::dnbctl
