#pragma once
// Explicit messaging on behalf of remote clients, in the transaction model of
// a DeviceNet scanner (2100-GK61 manual, "Using DeviceNet Explicit
// Messaging"): a request names a transaction (requester, txid) and a command
// (1 execute, 2 get status, 3 reset all); every request gets exactly one
// reply with a status code (1 success ... 15 connection busy) and, when the
// device answered, its CIP general/additional status and data. A repeated
// request is answered again, never executed twice.
//
// One gateway per port, owned by the port's loop like its Scanner. Sans-IO:
// requests and scanner results come in, replies go out as return values.
//
// Before a request is executed, the rack's ExplicitPolicy decides whether it
// may be: a refused one gets "invalid command" (8) and a message naming the
// [explicit_policy] key that would allow it, and is counted and logged with
// its requester.
#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bridge/common/log.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/rack/explicit_policy.hpp"

namespace dnbridge::rack {

enum class ExplicitCommand : std::uint8_t { kExecute = 1, kGetStatus = 2, kResetAll = 3 };

enum class TransactionStatus : std::uint8_t {
  kSuccess = 1,
  kInProgress = 2,
  kNotInScanList = 3,
  kSlaveOffline = 4,
  kPortOffline = 5,  // port disabled or off-line
  kTxidUnknown = 6,
  kInvalidCommand = 8,
  kOutOfBuffers = 9,
  kOtherTransaction = 10,  // other transaction in progress
  kCouldNotConnect = 11,
  kResponseTooLarge = 12,
  kInvalidPort = 13,
  kInvalidSize = 14,
  kConnectionBusy = 15,
};

std::string_view to_string(TransactionStatus status) noexcept;

// A request as received (the DDS layer copies its sample into this).
struct ExplicitCall {
  std::string requester;
  std::uint32_t txid = 0;
  std::uint8_t command = 0;
  std::string port;
  std::uint8_t mac = 0;  // as received: may be out of range
  std::uint8_t service = 0;
  std::uint16_t class_id = 0;
  std::uint16_t instance_id = 0;
  std::optional<std::uint8_t> attribute;
  std::vector<std::uint8_t> data;

  // The parts that make two executions the same request.
  bool same_request(const ExplicitCall& other) const;
};

struct ExplicitAnswer {
  std::string requester;
  std::uint32_t txid = 0;
  TransactionStatus status = TransactionStatus::kSuccess;
  std::uint8_t general_status = 0;  // the device's CIP general status; 0 when none
  std::uint8_t additional_status = cip::kNoAdditionalCode;
  std::vector<std::uint8_t> data;
  std::string message;
};

// A reply that refuses `call` without executing it.
ExplicitAnswer refuse(const ExplicitCall& call, TransactionStatus status, std::string message);

class ExplicitGateway {
 public:
  // Past a limit a request is answered at once with "out of buffers" (9):
  // one requester can neither take every slot nor make the others wait.
  struct Limits {
    std::size_t in_progress = 32;      // transactions executing at once, all requesters
    std::size_t per_requester = 8;     // of those, of one requester
    std::size_t retained = 256;        // completed transactions kept to answer repeats
    Duration retention = seconds(60);  // and for at most this long
  };

  explicit ExplicitGateway(devicenet::Scanner& scanner) : ExplicitGateway(scanner, Limits{}) {}
  ExplicitGateway(devicenet::Scanner& scanner, Limits limits)
      : ExplicitGateway(scanner, limits, ExplicitPolicy{}, Logger()) {}
  ExplicitGateway(devicenet::Scanner& scanner, Limits limits, ExplicitPolicy policy, Logger log);

  // A request for this gateway's port. Returns the reply to send now, if one
  // is due now (executions reply later, from on_result()).
  std::optional<ExplicitAnswer> on_request(const ExplicitCall& call, TimePoint now);
  // A result the scanner reported (ScannerObserver::on_explicit_result).
  // Returns the reply of the transaction it completes, if it is one of ours.
  std::optional<ExplicitAnswer> on_result(std::uint32_t request_id,
                                          const devicenet::ExplicitResult& result, TimePoint now);

  // Forgets the completed transactions kept longer than the retention: a
  // repeat of one of them is then executed again.
  void expire(TimePoint now);
  // The earliest time expire() has something to do; kNever when nothing.
  TimePoint next_expiry() const;

  std::size_t in_progress() const { return by_request_id_.size(); }
  std::size_t retained() const { return done_order_.size(); }
  // Requests the policy refused, in all and of one class.
  std::uint64_t refused_by_policy() const;
  std::uint64_t refused_by_policy(GuardedRequest kind) const {
    return refused_[static_cast<std::size_t>(kind)];
  }
  // Requests answered "out of buffers" because a limit was reached.
  std::uint64_t refused_for_limits() const { return refused_for_limits_; }
  const ExplicitPolicy& policy() const { return policy_; }
  // For requests taken from now on (a configuration read again).
  void set_policy(const ExplicitPolicy& policy) { policy_ = policy; }

 private:
  using Key = std::pair<std::string, std::uint32_t>;
  struct Transaction {
    ExplicitCall call;
    bool done = false;
    ExplicitAnswer answer;  // when done
    TimePoint done_at{};    // when done
  };

  std::optional<ExplicitAnswer> execute(const ExplicitCall& call, TimePoint now);
  // The refusal of a request the policy does not allow; nothing otherwise.
  std::optional<ExplicitAnswer> apply_policy(const ExplicitCall& call,
                                             const devicenet::RequestMessage& request,
                                             const devicenet::Node& node, TimePoint now);
  void log_allowed(const ExplicitCall& call, const devicenet::RequestMessage& request,
                   const devicenet::Node& node, TimePoint now);
  void retain(const Key& key);
  void forget_oldest();  // of the completed transactions
  std::optional<ExplicitAnswer> refuse_for_limits(const ExplicitCall& call, std::string message);

  devicenet::Scanner& scanner_;
  Limits limits_;
  ExplicitPolicy policy_;
  Logger log_;
  // Refusals go to the log with their requester; a requester that keeps
  // trying must not flood it.
  RateLimitedLog refusal_log_limit_{seconds(10), 5, "refusals"};
  RateLimitedLog allowed_log_limit_;
  std::array<std::uint64_t, kGuardedRequestKinds> refused_{};
  std::map<Key, Transaction> transactions_;
  std::map<std::uint32_t, Key> by_request_id_;  // executing
  std::uint64_t refused_for_limits_ = 0;
  std::deque<Key> done_order_;  // completed, oldest first
};

}  // namespace dnbridge::rack
