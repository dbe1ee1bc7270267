#pragma once
// Deterministic fault injection for the simulated bus: rules pick frames by
// identifier (with a mask) and optionally by sender, and drop, delay or corrupt
// them, either with a probability or for the next N matching frames. Draws come
// from a seeded std::mt19937_64, so one seed gives one run.
//
// Faults model what a misbehaving sender puts on the wire. A corrupted frame is
// delivered as corrupted: on a real bus a CRC error would be caught and the
// frame retransmitted, so only a faulty device can produce one that arrives.
#include <compare>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "bridge/can/can_frame.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::sim {

// The bus's name for an attached node; issued by VirtualBus::attach, never reused.
struct NodeHandle {
  std::uint32_t index = 0;
  friend auto operator<=>(const NodeHandle&, const NodeHandle&) = default;
};

enum class FaultAction : std::uint8_t { kDrop, kDelay, kCorrupt };

enum class Corruption : std::uint8_t {
  kFlipBits,  // flip `amount` distinct payload bits chosen by the PRNG
  kTruncate,  // remove the last `amount` bytes
  kExtend,    // append `amount` bytes of `fill` (at most up to 8 bytes)
};

struct FaultRule {
  // A frame matches when (frame.id & mask) == (id & mask); mask 0 matches all.
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
  std::optional<NodeHandle> sender;  // only frames sent by this node

  FaultAction action = FaultAction::kDrop;
  // With count 0 the rule fires on each matching frame with probability rate.
  // With count > 0 it fires on the next `count` matching frames, then is spent.
  double rate = 1.0;
  std::uint32_t count = 0;

  Duration delay{};  // kDelay: added to the time the frame reaches the bus
  Corruption corruption = Corruption::kFlipBits;
  std::uint8_t amount = 1;  // kCorrupt: bits flipped or bytes removed/added
  std::uint8_t fill = 0;    // kCorrupt/kExtend: value of appended bytes

  // Rules on one exact identifier.
  static FaultRule drop(std::uint32_t can_id) noexcept;
  static FaultRule delay_by(std::uint32_t can_id, Duration by) noexcept;
  static FaultRule corrupt(std::uint32_t can_id, Corruption how, std::uint8_t amount = 1) noexcept;
};

using RuleId = std::size_t;

enum class FaultOutcome : std::uint8_t { kPass, kDrop, kDelay, kCorrupt };

struct FaultResult {
  FaultOutcome outcome = FaultOutcome::kPass;
  Duration delay{};  // for kDelay
};

class FaultInjector {
 public:
  static constexpr std::uint64_t kDefaultSeed = 0x444E'4252'4944'4745;  // "DNBRIDGE"

  explicit FaultInjector(std::uint64_t seed = kDefaultSeed) noexcept : rng_(seed) {}

  RuleId add(const FaultRule& rule);
  // A removed rule stays in the table, inactive, so RuleIds stay valid.
  void remove(RuleId id) noexcept;
  void clear() noexcept;
  void reseed(std::uint64_t seed) noexcept { rng_.seed(seed); }

  // Rules are tried in the order added; the first that matches and fires
  // decides. A corrupt rule only matches frames it can change (flip and
  // truncate need data, extend needs room). May modify `frame`.
  FaultResult apply(can::CanFrame& frame, NodeHandle sender) noexcept;

  // Frames a rule matched, and how many of those it acted on.
  std::uint64_t matched(RuleId id) const noexcept;
  std::uint64_t fired(RuleId id) const noexcept;
  // Firings left of a next-N rule (0 when spent, removed or a rate rule).
  std::uint32_t remaining(RuleId id) const noexcept;
  bool active(RuleId id) const noexcept;

 private:
  struct Entry {
    FaultRule rule;
    std::uint32_t remaining = 0;
    bool active = true;
    std::uint64_t matched = 0;
    std::uint64_t fired = 0;
  };

  bool matches(const Entry& e, const can::CanFrame& frame, NodeHandle sender) const noexcept;
  bool draw(double rate) noexcept;
  void corrupt(const FaultRule& rule, can::CanFrame& frame) noexcept;

  std::mt19937_64 rng_;
  std::vector<Entry> rules_;
};

}  // namespace dnbridge::sim
