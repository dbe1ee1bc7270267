#include "adapters/dnbctl/requester.hpp"

#include <fmt/format.h>
#include <unistd.h>

namespace dnbridge::dnbctl {
namespace {

constexpr std::uint8_t kCommandExecute = 1;    // COMMAND_EXECUTE
constexpr std::uint8_t kStatusInProgress = 2;  // STATUS_IN_PROGRESS
constexpr dds::WaitSet::Token kReplies = 10;
// A request with no reply this long is written again.
constexpr Duration kRepeatAfter = seconds(1);

}  // namespace

std::string requester_name() {
  const auto started = std::chrono::duration_cast<std::chrono::milliseconds>(
                           std::chrono::system_clock::now().time_since_epoch())
                           .count();
  return fmt::format("dnbctl@{}:{}:{:x}", host_name(), getpid(), started);
}

Requester::Requester(Client& client, std::string requester, const std::string& rack)
    : requester_(std::move(requester)), transactions_(client, kReplies, std::span(&rack, 1)) {}

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

  if (!transactions_.await_reader(client, deadline)) return false;
  auto replies = transactions_.exchange(
      client, std::span(&request, 1), deadline, kRepeatAfter,
      [](const dnbridge_ExplicitReply& r) { return r.status != kStatusInProgress; });
  if (!replies.front()) return false;
  const dnbridge_ExplicitReply& r = replies.front()->data();
  x.status = r.status;
  x.general_status = r.general_status;
  x.additional_status = r.additional_status;
  const auto data = dds::view(r.data);
  x.data.assign(data.begin(), data.end());
  x.message = std::string(dds::view(r.message));
  return true;
}

}  // namespace dnbridge::dnbctl
