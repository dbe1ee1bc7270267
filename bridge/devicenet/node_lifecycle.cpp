// Node: the life cycle's explicit steps, from Allocate to the poll
// connection's expected packet rate, one handler per phase.
#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "bridge/cip/data_types.hpp"
#include "bridge/devicenet/node.hpp"
#include "bridge/devicenet/node_internal.hpp"

namespace dnbridge::devicenet {

using namespace node_detail;

void Node::issue(Step step, const RequestMessage& request, bool unconnected, TimePoint now,
                 std::optional<Duration> timeout) {
  // Kept so that a request lost on the bus can be sent again as it was.
  last_step_ = step;
  last_request_ = request;
  last_request_data_.assign(request.data);
  last_request_.data = last_request_data_.view();
  last_unconnected_ = unconnected;
  last_timeout_ = timeout;
  step_ = step;
  auto submitted = client_.submit(kInternalTag | static_cast<std::uint32_t>(step), request,
                                  unconnected, now, timeout);
  if (!submitted) {
    // Only a request larger than the message buffer can fail here: the
    // internal requests are small and external ones leave room in the queue.
    step_ = Step::kNone;
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("cannot send a life-cycle request: {}", submitted.error().message()),
                now);
  }
}

void Node::resend_step(TimePoint now) {
  const InlineBytes<64> data = last_request_data_;
  RequestMessage request = last_request_;
  request.data = data.view();
  issue(last_step_, request, last_unconnected_, now, last_timeout_);
}

void Node::get(Step step, std::uint16_t cls, std::uint16_t inst, std::uint8_t attr, TimePoint now) {
  RequestMessage r;
  r.service = static_cast<std::uint8_t>(cip::Service::kGetAttributeSingle);
  r.class_id = cls;
  r.instance_id = inst;
  r.attribute = attr;
  issue(step, r, false, now);
}

void Node::set(Step step, std::uint16_t cls, std::uint16_t inst, std::uint8_t attr, Bytes value,
               TimePoint now, std::optional<Duration> timeout) {
  RequestMessage r;
  r.service = static_cast<std::uint8_t>(cip::Service::kSetAttributeSingle);
  r.class_id = cls;
  r.instance_id = inst;
  r.attribute = attr;
  r.data = value;
  issue(step, r, false, now, timeout);
}

void Node::attempt_allocate(TimePoint now) {
  retry_at_ = kNever;
  step_timeouts_ = 0;
  ++counters_.allocate_attempts;
  const std::array<std::uint8_t, 2> data{allocation::kExplicit | allocation::kPoll,
                                         port_.master_mac.value()};
  RequestMessage r;
  r.service = static_cast<std::uint8_t>(cip::Service::kAllocateMasterSlave);
  r.class_id = kDeviceNetClass;
  r.instance_id = 1;
  r.data = Bytes(data);
  issue(Step::kAllocate, r, true, now);
}

void Node::release(Step step, TimePoint now) {
  const std::array<std::uint8_t, 1> data{allocation::kExplicit | allocation::kPoll};
  RequestMessage r;
  r.service = static_cast<std::uint8_t>(cip::Service::kReleaseMasterSlave);
  r.class_id = kDeviceNetClass;
  r.instance_id = 1;
  r.data = Bytes(data);
  issue(step, r, true, now);
}

void Node::on_explicit_result(std::uint32_t tag, const ExplicitResult& result, TimePoint now) {
  if (result.ok() || result.error == Errc::kDeviceError) last_explicit_answer_ = now;
  if ((tag & kInternalTag) == 0) {
    observer_.on_explicit_result(tag, config_.mac, result, now);
    return;
  }
  const auto step = static_cast<Step>(tag & 0xFF);
  if (step != step_) return;  // a cancelled step
  step_ = Step::kNone;
  on_step_result(step, result, now);
}

void Node::on_step_result(Step step, const ExplicitResult& r, TimePoint now) {
  if (r.error == Errc::kStopped) return;  // cancelled by shutdown or halt
  if (r.error == Errc::kDeviceError) record_device_error(r, now);
  if (r.error == Errc::kTimeout) record(NodeError::Kind::kExplicitTimeout, now);
  if (r.error == Errc::kAborted) record(NodeError::Kind::kExplicitAborted, now);
  if (r.error == Errc::kMalformed) record(NodeError::Kind::kExplicitMalformed, now);

  // Life-cycle requests on the explicit connection: a lost frame is retried,
  // a silent node is gone.
  const bool connected_step = step != Step::kAllocate && step != Step::kReleaseStale &&
                              step != Step::kReleaseFault && step != Step::kReleaseShutdown &&
                              step != Step::kKeepAlive;
  if (connected_step && r.error && r.error != Errc::kDeviceError) {
    if (++step_timeouts_ <= kStepTimeoutRetries) {
      resend_step(now);
      return;
    }
    lose(fmt::format("no answer from the explicit connection ({})", status_text(r)), now);
    return;
  }
  step_timeouts_ = 0;  // answered, even if with an error

  switch (step) {
    case Step::kNone:
      return;
    case Step::kAllocate:
      on_allocate_result(r, now);
      return;
    case Step::kReleaseStale:
      attempt_allocate(now);
      return;
    case Step::kVendor:
    case Step::kProductType:
    case Step::kProductCode:
      on_identity_result(step, r, now);
      return;
    case Step::kRevision:
    case Step::kSerial:
    case Step::kName:
      on_identity_info_result(step, r, now);
      return;
    case Step::kReadSetting:
    case Step::kWriteSetting:
      on_setting_result(step, r, now);
      return;
    case Step::kProducedPath:
    case Step::kConsumedPath:
      on_path_result(step, r, now);
      return;
    case Step::kProducedSize:
    case Step::kConsumedSize:
    case Step::kFallbackProducedSize:
    case Step::kFallbackConsumedSize:
      on_size_result(step, r, now);
      return;
    case Step::kExplicitEpr:
    case Step::kPollEpr:
      on_epr_result(step, r, now);
      return;
    case Step::kKeepAlive:
      on_keepalive_result(r, now);
      return;
    case Step::kReleaseFault:
      // Whatever the answer, the node is left alone until the re-check.
      connected_ = false;
      return;
    case Step::kReleaseShutdown:
      connected_ = false;
      set_state(NodeState::kStopped, "released by orderly shutdown", now);
      return;
  }
}

void Node::on_allocate_result(const ExplicitResult& r, TimePoint now) {
  if (r.ok()) {
    // The device is ours from here on: a fault below releases it.
    connected_ = true;
    auto format = decode_allocate_response_data(r.data.view());
    if (!format) {
      enter_fault(
          NodeState::kConfigurationFault,
          fmt::format("Allocate response has an unsupported body format ({})", hex(r.data.view())),
          now);
      return;
    }
    client_.set_body_format(*format);
    retry_delay_ = port_.allocate_retry_min;
    begin_identify(now);
    return;
  }
  if (r.error == Errc::kDeviceError) {
    if (r.general_status == cip::GeneralStatus::kObjectStateConflict &&
        r.additional_status == 0x01) {
      enter_fault(NodeState::kOwnedByOtherMaster,
                  "Allocate refused: owned by another master (0x0C/0x01)", now);
      return;
    }
    if (r.general_status == cip::GeneralStatus::kAlreadyInRequestedMode) {
      // Still allocated to this master from before (e.g. after a restart
      // of the master): release and allocate afresh.
      release(Step::kReleaseStale, now);
      return;
    }
    enter_fault(NodeState::kConfigurationFault, fmt::format("Allocate refused: {}", status_text(r)),
                now);
    return;
  }
  // No answer: the node is absent. Retry with back-off, forever.
  if (state_ != NodeState::kAbsent) {
    set_state(NodeState::kAbsent, fmt::format("no answer to Allocate ({})", status_text(r)), now);
  }
  retry_at_ = now + retry_delay_;
  retry_delay_ = std::min(retry_delay_ * 2, port_.allocate_retry_max);
}

// Vendor, product type and product code: the identity the scan list expects.
void Node::on_identity_result(Step step, const ExplicitResult& r, TimePoint now) {
  const auto value = r.ok() ? read_uint(r.data.view()) : std::nullopt;
  if (!value) {
    enter_fault(NodeState::kWrongDevice,
                fmt::format("Identity attribute {} unreadable: {}",
                            step == Step::kVendor        ? "vendor"
                            : step == Step::kProductType ? "product type"
                                                         : "product code",
                            r.ok() ? "bad size " + hex(r.data.view()) : status_text(r)),
                now);
    return;
  }
  const auto v = static_cast<std::uint16_t>(*value);
  if (step == Step::kVendor) {
    identity_.vendor_id = v;
    get(Step::kProductType, kIdentityClass, 1, 2, now);
  } else if (step == Step::kProductType) {
    identity_.product_type = v;
    get(Step::kProductCode, kIdentityClass, 1, 3, now);
  } else {
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
      return;
    }
    get(Step::kRevision, kIdentityClass, 1, 4, now);
  }
}

// Revision, serial number and name are information: a device that refuses
// them is still the expected device.
void Node::on_identity_info_result(Step step, const ExplicitResult& r, TimePoint now) {
  if (step == Step::kRevision) {
    if (r.ok() && r.data.size() >= 2) {
      identity_.major_revision = r.data[0];
      identity_.minor_revision = r.data[1];
    }
    get(Step::kSerial, kIdentityClass, 1, 6, now);
    return;
  }
  if (step == Step::kSerial) {
    // The CDN127 manual types the serial number UINT, the ODVA Identity
    // object UDINT: accept either.
    if (r.ok()) identity_.serial_number = read_uint(r.data.view()).value_or(0);
    get(Step::kName, kIdentityClass, 1, 7, now);
    return;
  }
  if (r.ok()) {
    if (auto name = cip::decode_short_string(r.data.view()); name) {
      identity_.product_name = std::string(*name);
    }
  }
  observer_.on_node_identity(config_.mac, identity_, now);
  set_state(NodeState::kConfiguring, "identity verified", now);
  setting_index_ = 0;
  next_setting(now);
}

void Node::on_setting_result(Step step, const ExplicitResult& r, TimePoint now) {
  const auto& s = config_.profile.settings[setting_index_];
  if (step == Step::kReadSetting) {
    if (!r.ok()) {
      enter_fault(NodeState::kConfigurationFault,
                  fmt::format("cannot read {}: {}", s.name, status_text(r)), now);
      return;
    }
    if (std::equal(r.data.view().begin(), r.data.view().end(), s.value.begin(), s.value.end())) {
      ++setting_index_;
      next_setting(now);
      return;
    }
    log_.info("{} is {}, setting {}", s.name, hex(r.data.view()), hex(Bytes(s.value)));
    set(Step::kWriteSetting, s.class_id, s.instance_id, s.attribute, Bytes(s.value), now);
    return;
  }
  if (!r.ok()) {
    enter_fault(
        NodeState::kConfigurationFault,
        fmt::format("device refused {} = {}: {}", s.name, hex(Bytes(s.value)), status_text(r)),
        now);
    return;
  }
  ++setting_index_;
  next_setting(now);
}

void Node::on_path_result(Step step, const ExplicitResult& r, TimePoint now) {
  if (!r.ok()) {
    const bool produced = step == Step::kProducedPath;
    enter_fault(
        NodeState::kConfigurationFault,
        fmt::format(
            "device refused the poll {} path {}: {}", produced ? "produced" : "consumed",
            hex(Bytes(produced ? config_.profile.produced_path : config_.profile.consumed_path)),
            status_text(r)),
        now);
    return;
  }
  if (step == Step::kProducedPath && !config_.profile.consumed_path.empty()) {
    set(Step::kConsumedPath, kConnectionClass, kPollConnection, kAttrConsumedPath,
        Bytes(config_.profile.consumed_path), now);
  } else {
    begin_verify(now);
  }
}

void Node::on_size_result(Step step, const ExplicitResult& r, TimePoint now) {
  const auto value = r.ok() ? read_uint(r.data.view()) : std::nullopt;
  const bool produced = step == Step::kProducedSize || step == Step::kFallbackProducedSize;
  const bool fallback = step == Step::kFallbackProducedSize || step == Step::kFallbackConsumedSize;
  const char* which = produced ? "produced" : "consumed";
  const auto answer = [&] { return r.ok() ? "bad size " + hex(r.data.view()) : status_text(r); };
  const auto& fb = config_.profile.size_fallback;
  if (!value) {
    if (!fallback && config_.profile.has_size_fallback) {
      // Connection 2 attributes 7/8 refused (older firmware answers 0x14,
      // attribute not supported): ask where the profile says the same sizes
      // are kept.
      size_refusal_ = fmt::format("{}: {}", size_attribute(produced, false), answer());
      log_.debug("poll {} size: {}; asking {}", which, size_refusal_,
                 size_attribute(produced, true));
      get(produced ? Step::kFallbackProducedSize : Step::kFallbackConsumedSize, fb.class_id,
          fb.instance_id, produced ? fb.produced_attribute : fb.consumed_attribute, now);
      return;
    }
    // The consumed size's own attribute was not asked when the produced
    // size's was refused: say so rather than name the other's refusal.
    const std::string first =
        !produced && produced_from_fallback_
            ? fmt::format("{} not asked ({})", size_attribute(false, false), size_refusal_)
            : size_refusal_;
    enter_fault(NodeState::kConfigurationFault,
                fallback ? fmt::format("cannot read the poll {} size: {}; fallback {}: {}", which,
                                       first, size_attribute(produced, true), answer())
                         : fmt::format("cannot read the poll {} size: {}: {}", which,
                                       size_attribute(produced, false), answer()),
                now);
    return;
  }
  if (produced) {
    produced_size_ = *value;
    produced_from_fallback_ = fallback;
    if (fallback) {
      // A device that refused attribute 7 refuses 8 too: ask the fallback
      // for the consumed size straight away.
      get(Step::kFallbackConsumedSize, fb.class_id, fb.instance_id, fb.consumed_attribute, now);
    } else {
      get(Step::kConsumedSize, kConnectionClass, kPollConnection, kAttrConsumedSize, now);
    }
  } else {
    consumed_size_ = *value;
    consumed_from_fallback_ = fallback;
    check_sizes(now);
  }
}

std::string Node::size_attribute(bool produced, bool fallback) const {
  if (!fallback) {
    return fmt::format("Connection {} attribute {}", kPollConnection,
                       produced ? kAttrProducedSize : kAttrConsumedSize);
  }
  const auto& fb = config_.profile.size_fallback;
  return fmt::format("{} (class 0x{:02X}) instance {} attribute {}",
                     fb.object_name.empty() ? "object" : fb.object_name, fb.class_id,
                     fb.instance_id, produced ? fb.produced_attribute : fb.consumed_attribute);
}

void Node::on_epr_result(Step step, const ExplicitResult& r, TimePoint now) {
  const bool poll = step == Step::kPollEpr;
  if (!r.ok()) {
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("device refused the {} connection's expected packet rate: {}",
                            poll ? "poll" : "explicit", status_text(r)),
                now);
    return;
  }
  // The device rounds EPR to its timer resolution and returns the value
  // it uses (devicenet-facts §5); a device that returns nothing keeps the
  // value asked.
  const Duration asked = poll ? config_.expected_packet_rate : config_.explicit_packet_rate;
  const auto actual = read_uint(r.data.view());
  const Duration epr = actual && *actual > 0 ? milliseconds(*actual) : asked;
  if (poll) {
    poll_epr_ = epr;
    go_online(now);
  } else {
    explicit_epr_ = epr;
    set_poll_epr(now);
  }
}

void Node::on_keepalive_result(const ExplicitResult& r, TimePoint now) {
  if (r.ok() || r.error == Errc::kDeviceError) {
    if (r.ok() && !r.data.empty() && device_state_ != r.data[0]) {
      device_state_ = r.data[0];
      observer_.on_device_state(config_.mac, r.data[0], now);
    }
    return;
  }
  // The device drops the explicit connection after 4 x EPR without a
  // request; single lost frames must not be taken for that. Try again at
  // once, and give up only when nothing has come back for that long.
  if (now - last_explicit_answer_ >= 4 * explicit_epr_) {
    lose(fmt::format("explicit connection lost: no answer for {} ms (4 x EPR; {})",
                     std::chrono::duration_cast<milliseconds>(now - last_explicit_answer_).count(),
                     status_text(r)),
         now);
    return;
  }
  keepalive_at_ = now;
}

void Node::begin_identify(TimePoint now) {
  set_state(NodeState::kIdentifying, "allocated: checking identity", now);
  get(Step::kVendor, kIdentityClass, 1, 1, now);
}

void Node::next_setting(TimePoint now) {
  const auto& settings = config_.profile.settings;
  if (setting_index_ < settings.size()) {
    const auto& s = settings[setting_index_];
    get(Step::kReadSetting, s.class_id, s.instance_id, s.attribute, now);
    return;
  }
  if (!config_.profile.produced_path.empty()) {
    set(Step::kProducedPath, kConnectionClass, kPollConnection, kAttrProducedPath,
        Bytes(config_.profile.produced_path), now);
  } else if (!config_.profile.consumed_path.empty()) {
    set(Step::kConsumedPath, kConnectionClass, kPollConnection, kAttrConsumedPath,
        Bytes(config_.profile.consumed_path), now);
  } else {
    begin_verify(now);
  }
}

void Node::begin_verify(TimePoint now) {
  set_state(NodeState::kVerifying, "configured: checking the poll connection's sizes", now);
  produced_size_.reset();
  consumed_size_.reset();
  produced_from_fallback_ = consumed_from_fallback_ = false;
  size_refusal_.clear();
  get(Step::kProducedSize, kConnectionClass, kPollConnection, kAttrProducedSize, now);
}

void Node::check_sizes(TimePoint now) {
  const auto& p = config_.profile;
  if (*produced_size_ != p.produced_size || *consumed_size_ != p.consumed_size) {
    // Never guess which of the two is right: say both, and where the
    // device's were read.
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("poll sizes differ: the device produces {} B ({}) and consumes {} B "
                            "({}); the configuration expects {} B and {} B ({})",
                            *produced_size_, size_attribute(true, produced_from_fallback_),
                            *consumed_size_, size_attribute(false, consumed_from_fallback_),
                            p.produced_size, p.consumed_size, p.format_description),
                now);
    return;
  }
  const std::uint16_t ms = to_ms(config_.explicit_packet_rate);
  const std::array<std::uint8_t, 2> value{static_cast<std::uint8_t>(ms & 0xFF),
                                          static_cast<std::uint8_t>(ms >> 8)};
  set(Step::kExplicitEpr, kConnectionClass, kExplicitConnection, kAttrExpectedPacketRate,
      Bytes(value), now);
}

void Node::set_poll_epr(TimePoint now) {
  // Last step before polling: setting EPR establishes the poll connection and
  // starts the device's 4 x EPR watchdog, so the first poll follows at once.
  // A lost answer is retried after 2 x EPR, while the connection still lives.
  const std::uint16_t ms = to_ms(config_.expected_packet_rate);
  const std::array<std::uint8_t, 2> value{static_cast<std::uint8_t>(ms & 0xFF),
                                          static_cast<std::uint8_t>(ms >> 8)};
  set(Step::kPollEpr, kConnectionClass, kPollConnection, kAttrExpectedPacketRate, Bytes(value), now,
      std::min(port_.explicit_messaging.response_timeout, 2 * config_.expected_packet_rate));
}

void Node::go_online(TimePoint now) {
  poll_outstanding_ = false;
  poll_unanswered_ = false;
  consecutive_errors_ = 0;
  last_response_ = now;
  last_explicit_answer_ = now;
  next_poll_ = next_poll_slot(now);
  keepalive_at_ = now + explicit_epr_;
  io_reassembler_.reset();
  std::string reason =
      fmt::format("polled every {} ms; EPR {} ms (explicit {} ms); {} B out, {} B in",
                  std::chrono::duration_cast<milliseconds>(config_.poll_period).count(),
                  std::chrono::duration_cast<milliseconds>(poll_epr_).count(),
                  std::chrono::duration_cast<milliseconds>(explicit_epr_).count(),
                  config_.profile.consumed_size, config_.profile.produced_size);
  if (produced_from_fallback_ || consumed_from_fallback_) {
    // Worth knowing about a device: it refused Connection 2 attributes 7/8.
    reason +=
        fmt::format(" (sizes read from {} and {})", size_attribute(true, produced_from_fallback_),
                    size_attribute(false, consumed_from_fallback_));
  }
  set_state(NodeState::kOnline, std::move(reason), now);
  // Outputs set before the node came online go out with the first poll.
  send_poll(now);
}

Status Node::request_explicit(std::uint32_t request_id, const RequestMessage& request,
                              TimePoint now) {
  if ((request_id & kInternalTag) != 0) return Errc::kOutOfRange;
  if (!connected_ || shutting_down_) return Errc::kNotConnected;
  // Two places stay free for the life cycle and the keep-alive.
  if (client_.queued() + 2 > ExplicitClient::kQueueCapacity) return Errc::kBusy;
  return client_.submit(request_id, request, false, now);
}

}  // namespace dnbridge::devicenet
