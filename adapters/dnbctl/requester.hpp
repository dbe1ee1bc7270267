#pragma once
// Explicit messaging through the bridge: one transaction (requester, txid)
// per request, a reply of the same key. The request topic is volatile, so a
// request is written once a bridge's reader matched and repeated while no
// reply came (the same key is the same transaction: the bridge answers a
// repeat with the same reply and never executes it twice). Each finished
// transaction's instance is unregistered: a reader keeps an instance for as
// long as a writer has it registered.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "adapters/dds/reader.hpp"
#include "adapters/dds/topic.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/dnbctl/client.hpp"
#include "adapters/dnbctl/format.hpp"

namespace dnbridge::dnbctl {

class Requester {
 public:
  // `requester`: unique per client process, e.g. "dnbctl@host:pid".
  Requester(Client& client, std::string requester);

  const std::string& name() const noexcept { return requester_; }

  // Executes x's request (COMMAND_EXECUTE, next txid) and fills x's reply
  // members. False when no reply came before the deadline (or an interrupt).
  bool execute(Client& client, ExplicitExchange& x, Deadline deadline);

 private:
  std::string requester_;
  std::uint32_t next_txid_ = 1;
  dds::Topic<dnbridge_ExplicitRequest> request_topic_;
  dds::Topic<dnbridge_ExplicitReply> reply_topic_;
  dds::Writer<dnbridge_ExplicitRequest> writer_;
  dds::Reader<dnbridge_ExplicitReply> reader_;
  dds::ReadCondition replies_;
};

}  // namespace dnbridge::dnbctl
