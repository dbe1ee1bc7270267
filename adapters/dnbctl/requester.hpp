#pragma once
// Requests to a bridge: one transaction (requester, txid) per request, a
// reply of the same key. The request topics (ExplicitRequest,
// BusScanRequest, ReloadRequest) are volatile, so a request is written once
// a bridge's reader matched and repeated while no reply came (the same key
// is the same transaction: the bridge answers a repeat with the same reply
// and never executes it twice). Each finished transaction's instance is
// unregistered: a reader keeps an instance for as long as a writer has it
// registered.
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topic.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/dnbctl/client.hpp"
#include "adapters/dnbctl/format.hpp"

namespace dnbridge::dnbctl {

// The requester name of this process: "dnbctl@host:pid:start", the start in
// ms since the epoch, hex. The start time makes the name unique even when a
// pid is reused while a bridge still remembers the transactions of an
// earlier dnbctl.
std::string requester_name();

// One kind of request and its reply (ExplicitRequest / ExplicitReply, ...):
// the request writer and the reply reader, with the contract's QoS
// (adapters/dds/topics.hpp), and the exchange of a few requests.
template <class Request, class Reply>
class Transactions {
 public:
  // `token`: the reply reader's in the client's waits, one per kind.
  // `racks`: those the requests are for; requests and replies are in their
  // partitions (dds::rack_partition), so that only their bridges get them.
  Transactions(Client& client, dds::WaitSet::Token token, std::span<const std::string> racks)
      : request_topic_(client.participant()),
        reply_topic_(client.participant()),
        writer_(client.participant(), request_topic_,
                dds::request_writer_qos(dds::rack_partitions(racks))),
        reader_(client.participant(), reply_topic_,
                dds::reply_reader_qos(dds::rack_partitions(racks))),
        replies_(reader_, DDS_ANY_STATE) {
    client.attach(replies_, token);
  }

  // Whether a bridge's request reader matched: a volatile request written
  // before is lost.
  bool reader_matched() const noexcept {
    auto n = writer_.matched_subscriptions();
    return n.ok() && *n > 0;
  }
  // Until one matched (true), the deadline or an interrupt.
  bool await_reader(Client& client, Deadline deadline) const {
    return client.wait_until(deadline, [&] { return reader_matched(); });
  }

  // Writes every request (requester and txid set, the txids distinct) now,
  // and again every `repeat` while its reply is missing, until each has its
  // reply, the deadline or an interrupt; then unregisters every request's
  // instance. A reply is a request's when its requester and txid are;
  // `is_final` false marks an interim reply (IN_PROGRESS: the final one
  // follows), which is skipped. The replies in the requests' order, none
  // where none came.
  std::vector<std::optional<dds::Sample<Reply>>> exchange(
      Client& client, std::span<const dds::Owned<Request>> requests, Deadline deadline,
      Duration repeat, const std::function<bool(const Reply&)>& is_final = {}) {
    std::vector<std::optional<dds::Sample<Reply>>> replies(requests.size());
    std::size_t missing = requests.size();
    auto next_write = std::chrono::steady_clock::now();
    const auto all_answered = [&] {
      if (auto taken = reader_.take()) {
        for (auto& sample : *taken) {
          if (!sample.valid_data()) continue;  // the bridge left (its writer unregistered)
          const Reply& r = sample.data();
          if (is_final && !is_final(r)) continue;
          for (std::size_t i = 0; i < requests.size(); ++i) {
            const Request& q = *requests[i];
            if (replies[i] || r.txid != q.txid ||
                dds::view(r.requester) != dds::view(q.requester)) {
              continue;
            }
            replies[i].emplace(std::move(sample));
            --missing;
            break;
          }
        }
      }
      if (missing == 0) return true;
      const auto now = std::chrono::steady_clock::now();
      if (now >= next_write) {
        // A failed write (a full history) is retried with the next repeat.
        for (std::size_t i = 0; i < requests.size(); ++i) {
          if (!replies[i]) (void)writer_.write(*requests[i]);
        }
        next_write = now + repeat;
      }
      return false;
    };
    (void)client.wait_until(deadline, all_answered);
    for (const auto& q : requests) (void)writer_.unregister_instance(*q);
    return replies;
  }

 private:
  dds::Topic<Request> request_topic_;
  dds::Topic<Reply> reply_topic_;
  dds::Writer<Request> writer_;
  dds::Reader<Reply> reader_;
  dds::ReadCondition replies_;
};

// Explicit messaging through the bridge (get, set, service).
class Requester {
 public:
  // `requester`: unique per client process (requester_name()); `rack`: the
  // rack whose bridge it asks.
  Requester(Client& client, std::string requester, const std::string& rack);

  const std::string& name() const noexcept { return requester_; }

  // Executes x's request (COMMAND_EXECUTE, next txid) and fills x's reply
  // members. False when no reply came before the deadline (or an interrupt).
  bool execute(Client& client, ExplicitExchange& x, Deadline deadline);

 private:
  std::string requester_;
  std::uint32_t next_txid_ = 1;
  Transactions<dnbridge_ExplicitRequest, dnbridge_ExplicitReply> transactions_;
};

}  // namespace dnbridge::dnbctl
