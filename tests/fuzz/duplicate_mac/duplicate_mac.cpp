// Duplicate MAC ID check messages, and the check itself driven by them.
// Input: [mac:1][payload...]. Properties: a payload that decodes re-encodes
// to the same 7 bytes; any other size is refused; the check fed the decoded
// message (and timers) never answers a response, never sends before it
// started and never leaves the duplicate state.
#include "bridge/devicenet/wire/duplicate_mac.hpp"

#include <cstddef>
#include <cstdint>

#include "bridge/devicenet/wire/identifier.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::devicenet;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const MacId mac = MacId::from_bits(data[0]);
  const Bytes payload(data + 1, size - 1);

  auto m = decode_duplicate_mac(payload);
  FUZZ_CHECK(m.ok() == (payload.size() == kDuplicateMacMessageSize));
  if (!m) return 0;
  FUZZ_CHECK(m->physical_port <= 127);
  auto frame = encode_duplicate_mac(mac, *m);
  FUZZ_CHECK(frame.ok());
  FUZZ_CHECK(frame->id == group2_id(mac, Group2Message::kDuplicateMacCheck));
  FUZZ_CHECK(frame->len == kDuplicateMacMessageSize);
  for (std::size_t i = 0; i < kDuplicateMacMessageSize; ++i)
    FUZZ_CHECK(frame->data[i] == payload[i]);
  auto again = decode_duplicate_mac(frame->payload());
  FUZZ_CHECK(again.ok() && *again == *m);

  // The check: the message arrives before start, in each window and online.
  DuplicateMacCheck check(mac, {});
  FUZZ_CHECK(!check.on_message(*m).has_value());
  FUZZ_CHECK(check.state() == DuplicateMacCheck::State::kIdle);
  TimePoint now = TimePoint{} + seconds(1);
  (void)check.start(now);
  const std::uint8_t when = data[0] >> 6;  // 0: first window, 1: second, 2+: online
  for (std::uint8_t i = 0; i < when && i < 2; ++i) {
    now = check.deadline();
    (void)check.on_timer(now);
  }
  const auto reply = check.on_message(*m);
  if (m->response) {
    FUZZ_CHECK(!reply.has_value());
    FUZZ_CHECK(check.state() == DuplicateMacCheck::State::kDuplicate);
  }
  if (reply) {
    FUZZ_CHECK(check.state() == DuplicateMacCheck::State::kOnline);
    auto r = decode_duplicate_mac(reply->payload());
    FUZZ_CHECK(r.ok() && r->response);
  }
  if (check.state() == DuplicateMacCheck::State::kDuplicate) {
    FUZZ_CHECK(!check.on_message(*m).has_value());
    FUZZ_CHECK(check.state() == DuplicateMacCheck::State::kDuplicate);
  }
  return 0;
}
