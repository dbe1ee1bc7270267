#include "bridge/rack/explicit_gateway.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace dnbridge::rack {

using devicenet::NodeState;

std::string_view to_string(TransactionStatus status) noexcept {
  switch (status) {
    case TransactionStatus::kSuccess:
      return "transaction completed";
    case TransactionStatus::kInProgress:
      return "transaction in progress";
    case TransactionStatus::kNotInScanList:
      return "slave not in scan list";
    case TransactionStatus::kSlaveOffline:
      return "slave off-line";
    case TransactionStatus::kPortOffline:
      return "port disabled or off-line";
    case TransactionStatus::kTxidUnknown:
      return "transaction TXID unknown";
    case TransactionStatus::kInvalidCommand:
      return "invalid command code";
    case TransactionStatus::kOutOfBuffers:
      return "out of buffers";
    case TransactionStatus::kOtherTransaction:
      return "other transaction in progress";
    case TransactionStatus::kCouldNotConnect:
      return "could not connect to slave";
    case TransactionStatus::kResponseTooLarge:
      return "response data too large";
    case TransactionStatus::kInvalidPort:
      return "invalid port";
    case TransactionStatus::kInvalidSize:
      return "invalid size";
    case TransactionStatus::kConnectionBusy:
      return "connection busy";
  }
  return "?";
}

bool ExplicitCall::same_request(const ExplicitCall& o) const {
  return port == o.port && mac == o.mac && service == o.service && class_id == o.class_id &&
         instance_id == o.instance_id && attribute == o.attribute && data == o.data;
}

ExplicitAnswer refuse(const ExplicitCall& call, TransactionStatus status, std::string message) {
  ExplicitAnswer a;
  a.requester = call.requester;
  a.txid = call.txid;
  a.status = status;
  a.message = std::move(message);
  return a;
}

ExplicitGateway::ExplicitGateway(devicenet::Scanner& scanner, Limits limits, ExplicitPolicy policy,
                                 Logger log)
    : scanner_(scanner), limits_(limits), policy_(policy), log_(std::move(log)) {}

std::uint64_t ExplicitGateway::refused_by_policy() const {
  std::uint64_t total = 0;
  for (auto n : refused_) total += n;
  return total;
}

std::optional<ExplicitAnswer> ExplicitGateway::on_request(const ExplicitCall& call, TimePoint now) {
  const Key key{call.requester, call.txid};
  switch (static_cast<ExplicitCommand>(call.command)) {
    case ExplicitCommand::kExecute: {
      auto it = transactions_.find(key);
      if (it == transactions_.end()) return execute(call, now);
      Transaction& t = it->second;
      if (!t.call.same_request(call)) {
        return refuse(call, TransactionStatus::kOtherTransaction,
                      t.done ? "this txid was used for another request: use a new txid, or reset"
                             : "another request with this txid is in progress");
      }
      // The same request again (a retransmission): answer it, never run it twice.
      if (t.done) return t.answer;
      return std::nullopt;  // its reply follows when it completes
    }
    case ExplicitCommand::kGetStatus: {
      auto it = transactions_.find(key);
      if (it == transactions_.end()) {
        return refuse(call, TransactionStatus::kTxidUnknown, "no transaction with this txid");
      }
      if (it->second.done) return it->second.answer;
      return refuse(call, TransactionStatus::kInProgress, "waiting for the device");
    }
    case ExplicitCommand::kResetAll: {
      // Forget this requester's completed transactions; those still running
      // complete, and are forgotten then.
      for (auto i = transactions_.begin(); i != transactions_.end();) {
        if (i->first.first == call.requester && i->second.done) {
          done_order_.erase(std::remove(done_order_.begin(), done_order_.end(), i->first),
                            done_order_.end());
          i = transactions_.erase(i);
        } else {
          ++i;
        }
      }
      for (auto& [id, k] : by_request_id_) {
        if (k.first == call.requester) transactions_.at(k).call.requester.clear();
      }
      auto a = refuse(call, TransactionStatus::kSuccess, "transactions reset");
      return a;
    }
  }
  return refuse(
      call, TransactionStatus::kInvalidCommand,
      fmt::format("command {} is not 1 (execute), 2 (get status) or 3 (reset all)", call.command));
}

std::optional<ExplicitAnswer> ExplicitGateway::execute(const ExplicitCall& call, TimePoint now) {
  const auto mac = devicenet::MacId::from(call.mac);
  const devicenet::Node* node = mac ? scanner_.node(*mac) : nullptr;
  if (!node) {
    return refuse(call, TransactionStatus::kNotInScanList,
                  fmt::format("MAC {} is not in the scan list of port {}", call.mac, call.port));
  }
  devicenet::RequestMessage request;
  request.service = call.service;
  request.class_id = call.class_id;
  request.instance_id = call.instance_id;
  request.attribute = call.attribute;
  request.data = Bytes(call.data);
  // Whatever state the port and the node are in, a request the policy
  // refuses is refused for what it is.
  if (auto refusal = apply_policy(call, request, *node, now)) return refusal;
  if (scanner_.state() != devicenet::PortState::kRunning) {
    return refuse(call, TransactionStatus::kPortOffline,
                  fmt::format("port {} is {}", call.port, devicenet::to_string(scanner_.state())));
  }
  switch (node->state()) {
    case NodeState::kAbsent:
    case NodeState::kStopped:
      return refuse(call, TransactionStatus::kSlaveOffline,
                    fmt::format("node {} is {}: {}", call.mac, devicenet::to_string(node->state()),
                                node->reason()));
    case NodeState::kWrongDevice:
    case NodeState::kConfigurationFault:
    case NodeState::kOwnedByOtherMaster:
    case NodeState::kDeviceFault:
      return refuse(call, TransactionStatus::kCouldNotConnect,
                    fmt::format("node {} is not connected ({}): {}", call.mac,
                                devicenet::to_string(node->state()), node->reason()));
    default:
      break;
  }
  if (call.data.size() > devicenet::kMaxExplicitMessage - 8) {
    return refuse(call, TransactionStatus::kInvalidSize,
                  fmt::format("{} bytes of service data: at most {}", call.data.size(),
                              devicenet::kMaxExplicitMessage - 8));
  }
  if (by_request_id_.size() >= limits_.in_progress) {
    return refuse_for_limits(call, fmt::format("{} transactions already in progress on port {}",
                                               by_request_id_.size(), call.port));
  }
  // Of at most limits_.in_progress, counted when asked.
  const auto executing = static_cast<std::size_t>(
      std::count_if(by_request_id_.begin(), by_request_id_.end(),
                    [&](const auto& entry) { return entry.second.first == call.requester; }));
  if (executing >= limits_.per_requester) {
    return refuse_for_limits(
        call, fmt::format("{} transactions of \"{}\" already in progress on port {} (at most {})",
                          executing, call.requester, call.port, limits_.per_requester));
  }

  auto id = scanner_.request_explicit(*mac, request, now);
  if (!id) {
    const auto& e = id.error();
    if (e == Errc::kBusy) {
      return refuse(call, TransactionStatus::kConnectionBusy,
                    "the node's explicit connection has requests queued");
    }
    if (e == Errc::kOutOfRange) {
      return refuse(call, TransactionStatus::kInvalidSize,
                    "the request does not fit the connection's body format");
    }
    if (e == Errc::kStopped) return refuse(call, TransactionStatus::kPortOffline, "port stopping");
    return refuse(call, TransactionStatus::kCouldNotConnect, e.message());
  }
  // What the policy lets through of the guarded requests is worth a trace.
  log_allowed(call, request, *node, now);
  const Key key{call.requester, call.txid};
  transactions_[key] = Transaction{call, false, {}, {}};
  by_request_id_[*id] = key;
  return std::nullopt;
}

std::optional<ExplicitAnswer> ExplicitGateway::refuse_for_limits(const ExplicitCall& call,
                                                                 std::string message) {
  ++refused_for_limits_;
  return refuse(call, TransactionStatus::kOutOfBuffers, std::move(message));
}

std::optional<ExplicitAnswer> ExplicitGateway::apply_policy(
    const ExplicitCall& call, const devicenet::RequestMessage& request, const devicenet::Node& node,
    TimePoint now) {
  const PolicyNode about{node.config().profile.settings};
  if (auto refusal = check(policy_, request, about)) {
    const std::uint64_t count = ++refused_[static_cast<std::size_t>(refusal->kind)];
    refusal_log_limit_.warn(
        log_, now,
        "explicit request from \"{}\" (txid {}) to node {} refused: {} ({} of this class "
        "refused so far)",
        call.requester, call.txid, call.mac, refusal->message, count);
    return refuse(call, TransactionStatus::kInvalidCommand, std::move(refusal->message));
  }
  return std::nullopt;
}

void ExplicitGateway::log_allowed(const ExplicitCall& call,
                                  const devicenet::RequestMessage& request,
                                  const devicenet::Node& node, TimePoint now) {
  const PolicyNode about{node.config().profile.settings};
  const auto guarded = classify(request, about);
  if (guarded.empty()) return;
  allowed_log_limit_.info(
      log_, now, "explicit request from \"{}\" (txid {}) to node {} sent: {}, allowed by {}",
      call.requester, call.txid, call.mac, guarded.front().what, policy_key(guarded.front().kind));
}

std::optional<ExplicitAnswer> ExplicitGateway::on_result(std::uint32_t request_id,
                                                         const devicenet::ExplicitResult& result,
                                                         TimePoint now) {
  auto it = by_request_id_.find(request_id);
  if (it == by_request_id_.end()) return std::nullopt;
  const Key key = it->second;
  by_request_id_.erase(it);
  Transaction& t = transactions_.at(key);

  ExplicitAnswer a = refuse(t.call, TransactionStatus::kSuccess, {});
  a.requester = key.first;
  if (result.ok() || result.error == Errc::kDeviceError) {
    // The device answered: the transaction is complete, whatever it said.
    a.general_status = static_cast<std::uint8_t>(result.general_status);
    a.additional_status = result.additional_status;
    a.data.assign(result.data.view().begin(), result.data.view().end());
    if (result.ok()) {
      a.message = "success";
    } else {
      const auto name = cip::to_string(result.general_status);
      a.message = fmt::format("device error 0x{:02X}/0x{:02X}: {}", a.general_status,
                              a.additional_status, name.empty() ? "reserved status" : name);
    }
  } else if (result.error == Errc::kOutOfRange) {
    a.status = TransactionStatus::kResponseTooLarge;
    a.message =
        fmt::format("the device's response is over {} bytes", devicenet::kMaxExplicitMessage);
  } else if (result.error == Errc::kStopped) {
    a.status = TransactionStatus::kPortOffline;
    a.message = "port stopped before the device answered";
  } else {
    a.status = TransactionStatus::kSlaveOffline;
    a.message = fmt::format("no usable answer from the device: {}", result.error.message());
  }

  if (t.call.requester.empty()) {
    // Its requester reset while it ran: nobody keeps it.
    transactions_.erase(key);
    return a;
  }
  t.done = true;
  t.answer = a;
  t.done_at = now;
  retain(key);
  return a;
}

void ExplicitGateway::retain(const Key& key) {
  done_order_.push_back(key);
  while (done_order_.size() > limits_.retained) forget_oldest();
}

void ExplicitGateway::expire(TimePoint now) {
  while (!done_order_.empty() &&
         now >= transactions_.at(done_order_.front()).done_at + limits_.retention) {
    forget_oldest();
  }
}

TimePoint ExplicitGateway::next_expiry() const {
  if (done_order_.empty()) return kNever;
  return transactions_.at(done_order_.front()).done_at + limits_.retention;
}

void ExplicitGateway::forget_oldest() {
  transactions_.erase(done_order_.front());
  done_order_.pop_front();
}

}  // namespace dnbridge::rack
