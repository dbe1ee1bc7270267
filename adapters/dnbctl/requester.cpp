#include "adapters/dnbctl/requester.hpp"

#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"

namespace dnbridge::dnbctl {
namespace {

constexpr std::uint8_t kCommandExecute = 1;  // COMMAND_EXECUTE
constexpr std::uint8_t kStatusInProgress = 2;  // STATUS_IN_PROGRESS
constexpr dds::WaitSet::Token kReplies = 10;
// A request with no reply this long is written again.
constexpr Duration kRepeatAfter = seconds(1);

}  // namespace

Requester::Requester(Client& client, std::string requester)
    : requester_(std::move(requester)),
      request_topic_(client.participant()),
      reply_topic_(client.participant()),
      writer_(client.participant(), request_topic_, dds::request_writer_qos()),
      reader_(client.participant(), reply_topic_, dds::reply_reader_qos()),
      replies_(reader_, DDS_ANY_STATE) {
  client.attach(replies_, kReplies);
}

bool Requester::execute(Client& client, ExplicitExchange& x, Deadline deadline) {
  dds::Owned<dnbridge_ExplicitRequest> request;
  dds::set_string(request->requester, requester_);
  request->txid = next_txid_++;
  request->command = kCommandExecute;
  dds::set_string(request->rack, x.rack);
  dds::set_string(request->port, x.port);
  request->mac = x.mac;
  request->service = x.service;
  request->class_id = x.class_id;
  request->instance_id = x.instance_id;
  request->has_attribute = x.attribute.has_value();
  request->attribute_id = x.attribute.value_or(0);
  dds::set_octets(request->data, x.request_data);

  // Until a bridge's request reader matched: a volatile request written
  // before is lost.
  if (!client.wait_until(deadline, [&] {
        auto n = writer_.matched_subscriptions();
        return n.ok() && *n > 0;
      })) {
    return false;
  }

  bool answered = false;
  auto next_write = std::chrono::steady_clock::now();
  const auto take_reply = [&] {
    auto samples = reader_.take();
    if (!samples) return;
    for (const auto& s : *samples) {
      if (!s.valid_data()) continue;  // the bridge left (its writer unregistered)
      const auto& r = s.data();
      if (dds::view(r.requester) != requester_ || r.txid != request->txid) continue;
      if (r.status == kStatusInProgress) continue;  // the final reply follows
      x.status = r.status;
      x.general_status = r.general_status;
      x.additional_status = r.additional_status;
      const auto data = dds::view(r.data);
      x.data.assign(data.begin(), data.end());
      x.message = std::string(dds::view(r.message));
      answered = true;
    }
  };
  client.wait_until(deadline, [&] {
    take_reply();
    if (answered) return true;
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_write) {
      // A failed write (a full history) is retried with the next repeat.
      (void)writer_.write(*request);
      next_write = now + kRepeatAfter;
    }
    return false;
  });
  (void)writer_.unregister_instance(*request);
  return answered;
}

}  // namespace dnbridge::dnbctl
