// Node: the start-up's handlers from the allocation to the configuration:
// the explicit and poll connections allocated, the identity checked, and the
// profile's settings read, written where they differ and read back. Each
// records what an answer says and gives its verdict; where a verdict leads
// is the table's (kStartup, node_lifecycle.cpp).
#include <fmt/format.h>

#include <algorithm>

#include "bridge/cip/data_types.hpp"
#include "bridge/cip/identity_health.hpp"
#include "bridge/devicenet/master/node.hpp"
#include "bridge/devicenet/master/node_internal.hpp"

namespace dnbridge::devicenet {

using namespace node_detail;

namespace {

namespace ident = cip::identity;

}  // namespace

// --- allocation ----------------------------------------------------------------

Node::Verdict Node::after_allocate_explicit(const ExplicitResult& r, TimePoint now) {
  if (r.ok()) {
    // The device is ours from here on: a fault below releases it.
    connected_ = true;
    auto format = decode_allocate_response_data(r.data.view());
    if (!format) {
      enter_fault(
          NodeState::kConfigurationFault,
          fmt::format("Allocate response has an unsupported body format ({})", hex(r.data.view())),
          now);
      return Verdict::kStop;
    }
    client_.set_body_format(*format);
    return Verdict::kNext;
  }
  if (r.error == Errc::kDeviceError) {
    if (r.general_status == cip::GeneralStatus::kObjectStateConflict &&
        r.additional_status == 0x01) {
      enter_fault(NodeState::kOwnedByOtherMaster,
                  "Allocate refused: owned by another master (0x0C/0x01)", now);
      return Verdict::kStop;
    }
    if (r.general_status == cip::GeneralStatus::kAlreadyInRequestedMode) {
      // Still allocated to this master from before (a restart of the
      // master): release and allocate afresh, to learn its body format.
      return Verdict::kAlt;
    }
    enter_fault(NodeState::kConfigurationFault, fmt::format("Allocate refused: {}", status_text(r)),
                now);
    return Verdict::kStop;
  }
  // No answer: the node is absent. Retry with back-off, forever.
  if (state_ != NodeState::kAbsent) {
    set_state(NodeState::kAbsent, fmt::format("no answer to Allocate ({})", status_text(r)), now);
  }
  retry_at_ = now + next_backoff();
  return Verdict::kStop;
}

Node::Verdict Node::after_release_stale(const ExplicitResult&, TimePoint now) {
  // Whatever the answer, allocate again after a back-off: a device that
  // keeps saying "already allocated" is not asked more often than that.
  retry_at_ = now + next_backoff();
  return Verdict::kStop;
}

Node::Verdict Node::after_allocation_info(const ExplicitResult& r, TimePoint) {
  // I/O connections left from before (this master's, restarted) are
  // released: they are made afresh once the configuration is in place.
  constexpr std::uint8_t kIo = allocation::kPoll | allocation::kBitStrobe |
                               allocation::kMulticastPoll | allocation::kChangeOfState |
                               allocation::kCyclic;
  if (r.ok() && !r.data.empty() && (r.data[0] & kIo) != 0) {
    stale_choice_ = static_cast<std::uint8_t>(r.data[0] & kIo);
    log_.info("I/O connections are still allocated from before (0x{:02X}): releasing them",
              stale_choice_);
    return Verdict::kAlt;
  }
  return Verdict::kNext;
}

Node::Verdict Node::after_allocate_poll(const ExplicitResult& r, TimePoint now) {
  if (r.ok()) {
    poll_.allocation().allocated = true;
    return Verdict::kNext;
  }
  return io_allocate_refused(r, now, "Allocate of the poll connection", "", poll_.allocation());
}

Node::Verdict Node::io_allocate_refused(const ExplicitResult& r, TimePoint now,
                                        std::string_view what, std::string_view needed_by,
                                        IoAllocation& allocation) {
  // Held already (its answer to an Allocate lost on the bus, or left from
  // before): released, then allocated once more.
  if (r.general_status == cip::GeneralStatus::kAlreadyInRequestedMode &&
      !allocation.release_tried) {
    allocation.release_tried = true;
    return Verdict::kAlt;
  }
  allocation.requested = false;  // refused: the device did not give it
  if (r.general_status == cip::GeneralStatus::kObjectStateConflict && r.additional_status == 0x01) {
    enter_fault(NodeState::kOwnedByOtherMaster,
                fmt::format("{} refused: owned by another master (0x0C/0x01)", what), now);
    return Verdict::kStop;
  }
  enter_fault(NodeState::kConfigurationFault,
              fmt::format("{} refused: {}{}", what, status_text(r), needed_by), now);
  return Verdict::kStop;
}

// --- identity ------------------------------------------------------------------

// Vendor, product type and product code: the identity the scan list expects.
Node::Verdict Node::after_identity_match(const ExplicitResult& r, TimePoint now) {
  const auto value = read_uint(r.data.view());
  if (!value) {
    enter_fault(
        NodeState::kWrongDevice,
        fmt::format("{} unreadable: bad size {}", target_of(last_step_).name, hex(r.data.view())),
        now);
    return Verdict::kStop;
  }
  const auto v = static_cast<std::uint16_t>(*value);
  if (last_step_ == Step::kVendor) {
    identity_.vendor_id = v;
    return Verdict::kNext;
  }
  if (last_step_ == Step::kProductType) {
    identity_.product_type = v;
    return Verdict::kNext;
  }
  identity_.product_code = v;
  const auto& want = config_.profile.identity;
  if (identity_.vendor_id != want.vendor_id || identity_.product_type != want.product_type ||
      identity_.product_code != want.product_code) {
    enter_fault(NodeState::kWrongDevice,
                fmt::format("expected vendor {} product type {} product code {}, found "
                            "vendor {} product type {} product code {}",
                            want.vendor_id, want.product_type, want.product_code,
                            identity_.vendor_id, identity_.product_type, identity_.product_code),
                now);
    return Verdict::kStop;
  }
  return Verdict::kNext;
}

// Revision, name and status are information: a device that refuses them is
// still the expected device.
// (A refused one is cleared: it may be another device than last time.)
Node::Verdict Node::after_revision(const ExplicitResult& r, TimePoint) {
  const bool ok = r.ok() && r.data.size() >= 2;
  identity_.major_revision = ok ? r.data[0] : 0;
  identity_.minor_revision = ok ? r.data[1] : 0;
  return Verdict::kNext;
}

Node::Verdict Node::after_serial(const ExplicitResult& r, TimePoint now) {
  // The CDN127 manual types the serial number UINT, the ODVA Identity object
  // UDINT: either is taken.
  const auto serial = r.ok() ? read_uint(r.data.view()) : std::nullopt;
  if (config_.serial_number) {
    if (!serial) {
      enter_fault(NodeState::kWrongDevice,
                  fmt::format("cannot check the configured serial number 0x{:08X}: {} {}",
                              *config_.serial_number, ident::kSerialNumber.name,
                              r.ok() ? "bad size " + hex(r.data.view()) : status_text(r)),
                  now);
      return Verdict::kStop;
    }
    if (*serial != *config_.serial_number) {
      enter_fault(NodeState::kWrongDevice,
                  fmt::format("serial number 0x{:08X}, the configuration expects 0x{:08X} "
                              "(a swapped module, or a misset MAC switch?)",
                              *serial, *config_.serial_number),
                  now);
      return Verdict::kStop;
    }
  }
  identity_.serial_number = serial.value_or(0);
  if (serial) {
    if (first_serial_ && *first_serial_ != *serial) {
      log_.warn("serial number changed from 0x{:08X} to 0x{:08X}: another device at this MAC",
                *first_serial_, *serial);
    }
    first_serial_ = *serial;
  }
  return Verdict::kNext;
}

Node::Verdict Node::after_name(const ExplicitResult& r, TimePoint) {
  identity_.product_name.clear();
  if (!r.ok()) return Verdict::kNext;
  if (auto name = cip::decode_short_string(r.data.view()); name) {
    identity_.product_name = std::string(*name);
  }
  return Verdict::kNext;
}

Node::Verdict Node::after_identity_status(const ExplicitResult& r, TimePoint) {
  identity_.status.reset();
  if (r.ok() && r.data.size() == 2)
    identity_.status = static_cast<std::uint16_t>(*read_uint(r.data.view()));
  if (!r.ok()) log_.info("{} not readable ({})", ident::kStatus.name, status_text(r));
  note_minor_faults();
  return Verdict::kNext;
}

Node::Verdict Node::after_identity_state(const ExplicitResult& r, TimePoint now) {
  // Optional in the Identity object: a device without it (0x14 attribute
  // not supported, or 0x08 service not supported) is not at fault; its
  // state is unknown and the keep-alive reads Identity.Status instead.
  identity_.state.reset();
  keep_alive_.set_state_supported(r.ok());
  if (r.ok() && r.data.size() == 1) {
    identity_.state = r.data[0];
    if (device_state_ != r.data[0]) {
      device_state_ = r.data[0];
      observer_.on_device_state(config_.mac, r.data[0], now);
    }
  } else if (!r.ok()) {
    log_.info("{} not supported ({}): state unknown", ident::kState.name, status_text(r));
  }
  observer_.on_node_identity(config_.mac, identity_, now);
  if (!check_health(now)) return Verdict::kStop;
  // The settings, then the checks, from the first.
  setting_index_ = 0;
  setting_retried_ = false;
  settings_in_force_.assign(config_.profile.settings.size(), {});
  check_index_ = 0;
  return Verdict::kNext;
}

// --- configuration ---------------------------------------------------------------

std::string Node::setting_expectation(Step step) const {
  if (step != Step::kReadSetting && step != Step::kVerifySetting) return {};
  const auto& s = config_.profile.settings[setting_index_];
  if (s.keep_device_value) {
    return fmt::format("; the device's own value is kept: expected {} byte(s), 0..{}",
                       s.value.size(), s.device_value_max);
  }
  return fmt::format("; the configuration needs {}", hex(Bytes(s.value)));
}

bool Node::has_setting() const { return setting_index_ < config_.profile.settings.size(); }

bool Node::has_check() const { return check_index_ < config_.profile.checks.size(); }

void Node::next_setting(Bytes in_force) {
  settings_in_force_[setting_index_].assign(in_force.begin(), in_force.end());
  ++setting_index_;
  setting_retried_ = false;
}

void Node::ask_setting(Ask& ask, TimePoint) {
  ask.value.assign(Bytes(config_.profile.settings[setting_index_].value));
}

void Node::ask_stale_io(Ask& ask, TimePoint) { ask.choice = stale_choice_; }

Node::Verdict Node::after_check(const ExplicitResult& r, TimePoint now) {
  const auto& c = config_.profile.checks[check_index_];
  ++check_index_;
  if (!r.ok()) {
    // Not offered (service, attribute or object not there): not compared.
    // Any other refusal leaves the device unchecked: a fault, not a guess.
    using cip::GeneralStatus;
    const auto g = r.general_status;
    if (g == GeneralStatus::kServiceNotSupported || g == GeneralStatus::kAttributeNotSupported ||
        g == GeneralStatus::kObjectDoesNotExist || g == GeneralStatus::kPathDestinationUnknown) {
      log_.info("{} not offered ({}): not compared", c.name, status_text(r));
      return Verdict::kAgain;
    }
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("{} could not be read ({}): the device is not checked against what "
                            "the configuration expects",
                            c.name, status_text(r)),
                now);
    return Verdict::kStop;
  }
  const auto differences =
      c.verifier ? c.verifier->differences(r.data.view()) : std::vector<std::string>{};
  if (!differences.empty()) {
    std::string text;
    for (const auto& d : differences) text += (text.empty() ? "" : "; ") + d;
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("{} differs from what the configuration expects: {}", c.name, text),
                now);
    return Verdict::kStop;
  }
  return Verdict::kAgain;
}

Node::Verdict Node::after_read_setting(const ExplicitResult& r, TimePoint now) {
  const auto& s = config_.profile.settings[setting_index_];
  const bool equal =
      std::equal(r.data.view().begin(), r.data.view().end(), s.value.begin(), s.value.end());
  if (s.keep_device_value) {
    const auto v = read_uint(r.data.view());
    if (r.data.size() != s.value.size() || !v || *v > s.device_value_max) {
      enter_fault(NodeState::kConfigurationFault,
                  fmt::format("{} reads {}: expected {} byte(s), 0..{} (the device's own value "
                              "is kept, but this one is not one the profile knows)",
                              s.name, hex(r.data.view()), s.value.size(), s.device_value_max),
                  now);
      return Verdict::kStop;
    }
    log_.info("{} is {}: the device's own, kept", s.name, hex(r.data.view()));
  }
  if (equal || s.keep_device_value) {
    next_setting(r.data.view());
    return Verdict::kAgain;
  }
  log_.info("{} is {}, setting {}", s.name, hex(r.data.view()), hex(Bytes(s.value)));
  setting_found_.assign(r.data.view());
  return Verdict::kAlt;
}

Node::Verdict Node::after_write_setting(const ExplicitResult& r, TimePoint now) {
  const auto& s = config_.profile.settings[setting_index_];
  if (r.ok()) {
    ++counters_.settings_written;
    return Verdict::kNext;
  }
  // A device that takes no configuration while a poll connection exists
  // (CDN127 manual, Configuration object NOTE 1): release it, try once more.
  if (r.general_status == cip::GeneralStatus::kObjectStateConflict && !setting_retried_) {
    setting_retried_ = true;
    log_.info("device refused {} = {} ({}): releasing the poll connection and trying again", s.name,
              hex(Bytes(s.value)), status_text(r));
    return Verdict::kAlt;
  }
  enter_fault(NodeState::kConfigurationFault,
              fmt::format("device refused Set {} = {}: {}; it has {}", s.name, hex(Bytes(s.value)),
                          status_text(r), hex(setting_found_.view())),
              now);
  return Verdict::kStop;
}

Node::Verdict Node::after_release_for_setting(const ExplicitResult&, TimePoint) {
  // "Not allocated" (0x0B) or done: either way no poll connection is left.
  poll_.allocation().forget();
  return Verdict::kNext;
}

Node::Verdict Node::after_verify_setting(const ExplicitResult& r, TimePoint now) {
  const auto& s = config_.profile.settings[setting_index_];
  if (!std::equal(r.data.view().begin(), r.data.view().end(), s.value.begin(), s.value.end())) {
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("{} reads {} after the device took {}", s.name, hex(r.data.view()),
                            hex(Bytes(s.value))),
                now);
    return Verdict::kStop;
  }
  next_setting(r.data.view());
  return Verdict::kNext;
}

}  // namespace dnbridge::devicenet
