#include "adapters/sim/bus/fault_injection.hpp"

#include <algorithm>
#include <array>
#include <utility>

namespace dnbridge::sim {

FaultRule FaultRule::drop(std::uint32_t can_id) noexcept {
  FaultRule r;
  r.id = can_id;
  r.mask = can::kMaxStandardId;
  r.action = FaultAction::kDrop;
  return r;
}

FaultRule FaultRule::delay_by(std::uint32_t can_id, Duration by) noexcept {
  FaultRule r = drop(can_id);
  r.action = FaultAction::kDelay;
  r.delay = by;
  return r;
}

FaultRule FaultRule::corrupt(std::uint32_t can_id, Corruption how, std::uint8_t amount) noexcept {
  FaultRule r = drop(can_id);
  r.action = FaultAction::kCorrupt;
  r.corruption = how;
  r.amount = amount;
  return r;
}

RuleId FaultInjector::add(const FaultRule& rule) {
  rules_.push_back(Entry{rule, rule.count, true, 0, 0});
  return rules_.size() - 1;
}

void FaultInjector::remove(RuleId id) noexcept {
  if (id < rules_.size()) rules_[id].active = false;
}

void FaultInjector::clear() noexcept {
  for (Entry& e : rules_) e.active = false;
}

std::uint64_t FaultInjector::matched(RuleId id) const noexcept {
  return id < rules_.size() ? rules_[id].matched : 0;
}

std::uint64_t FaultInjector::fired(RuleId id) const noexcept {
  return id < rules_.size() ? rules_[id].fired : 0;
}

std::uint32_t FaultInjector::remaining(RuleId id) const noexcept {
  return id < rules_.size() && rules_[id].active ? rules_[id].remaining : 0;
}

bool FaultInjector::active(RuleId id) const noexcept {
  return id < rules_.size() && rules_[id].active;
}

bool FaultInjector::matches(const Entry& e, const can::CanFrame& frame,
                            NodeHandle sender) const noexcept {
  const FaultRule& r = e.rule;
  if (!e.active) return false;
  if ((frame.id & r.mask) != (r.id & r.mask)) return false;
  if (r.sender && *r.sender != sender) return false;
  if (r.action == FaultAction::kCorrupt) {
    switch (r.corruption) {
      case Corruption::kFlipBits:
      case Corruption::kTruncate:
        return frame.len > 0 && r.amount > 0;
      case Corruption::kExtend:
        return frame.len < can::kMaxDataLength && r.amount > 0;
    }
  }
  return true;
}

bool FaultInjector::draw(double rate) noexcept {
  if (rate >= 1.0) return true;
  if (rate <= 0.0) return false;
  // 53 random bits to a double in [0, 1): the same sequence with any standard
  // library, unlike std::uniform_real_distribution.
  const double u = static_cast<double>(rng_() >> 11) * 0x1.0p-53;
  return u < rate;
}

void FaultInjector::corrupt(const FaultRule& rule, can::CanFrame& frame) noexcept {
  const std::size_t len = std::min<std::size_t>(frame.len, can::kMaxDataLength);
  switch (rule.corruption) {
    case Corruption::kFlipBits: {
      // Partial Fisher-Yates over the payload's bit positions: distinct bits.
      std::array<std::uint8_t, 8 * can::kMaxDataLength> positions{};
      const std::size_t bits = 8 * len;
      for (std::size_t i = 0; i < bits; ++i) positions[i] = static_cast<std::uint8_t>(i);
      const std::size_t flips = std::min<std::size_t>(rule.amount, bits);
      for (std::size_t i = 0; i < flips; ++i) {
        const std::size_t j = i + static_cast<std::size_t>(rng_() % (bits - i));
        std::swap(positions[i], positions[j]);
        const std::uint8_t p = positions[i];
        frame.data[p / 8] = static_cast<std::uint8_t>(frame.data[p / 8] ^ (0x80U >> (p % 8)));
      }
      break;
    }
    case Corruption::kTruncate:
      frame.len = static_cast<std::uint8_t>(len - std::min<std::size_t>(rule.amount, len));
      break;
    case Corruption::kExtend: {
      const std::size_t new_len = std::min<std::size_t>(len + rule.amount, can::kMaxDataLength);
      for (std::size_t i = len; i < new_len; ++i) frame.data[i] = rule.fill;
      frame.len = static_cast<std::uint8_t>(new_len);
      break;
    }
  }
}

FaultResult FaultInjector::apply(can::CanFrame& frame, NodeHandle sender) noexcept {
  for (Entry& e : rules_) {
    if (!matches(e, frame, sender)) continue;
    ++e.matched;
    if (e.rule.count > 0) {
      if (--e.remaining == 0) e.active = false;
    } else if (!draw(e.rule.rate)) {
      continue;
    }
    ++e.fired;
    switch (e.rule.action) {
      case FaultAction::kDrop:
        return {FaultOutcome::kDrop, {}};
      case FaultAction::kDelay:
        return {FaultOutcome::kDelay, e.rule.delay};
      case FaultAction::kCorrupt:
        corrupt(e.rule, frame);
        return {FaultOutcome::kCorrupt, {}};
    }
  }
  return {};
}

}  // namespace dnbridge::sim
