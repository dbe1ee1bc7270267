#include "bridge/devicenet/node.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "bridge/cip/data_types.hpp"
#include "bridge/devicenet/identifier.hpp"

namespace dnbridge::devicenet {
namespace {

// The DeviceNet objects the life cycle addresses (ODVA common objects).
constexpr std::uint16_t kIdentityClass = 0x01;
constexpr std::uint16_t kConnectionClass = 0x05;
constexpr std::uint16_t kExplicitConnection = 1;
constexpr std::uint16_t kPollConnection = 2;
constexpr std::uint8_t kAttrProducedSize = 7;
constexpr std::uint8_t kAttrConsumedSize = 8;
constexpr std::uint8_t kAttrExpectedPacketRate = 9;
constexpr std::uint8_t kAttrProducedPath = 14;
constexpr std::uint8_t kAttrConsumedPath = 16;
constexpr std::uint8_t kIdentityState = 8;

// Life-cycle reads that time out are retried this many times before the node
// is taken for gone: single lost frames must not cost a reconnection.
constexpr unsigned kStepTimeoutRetries = 2;

std::uint16_t to_ms(Duration d) {
  const auto ms = std::chrono::duration_cast<milliseconds>(d).count();
  return static_cast<std::uint16_t>(std::clamp<std::int64_t>(ms, 0, 0xFFFF));
}

std::optional<std::uint32_t> read_uint(Bytes data) {
  ByteReader r(data);
  if (data.size() == 1) return r.u8();
  if (data.size() == 2) return r.u16le();
  if (data.size() == 4) return r.u32le();
  return std::nullopt;
}

std::string status_text(const ExplicitResult& r) {
  if (r.error == Errc::kDeviceError) {
    auto name = cip::to_string(r.general_status);
    return fmt::format("{} (0x{:02X}/0x{:02X})", name.empty() ? "reserved status" : name,
                       static_cast<unsigned>(r.general_status), r.additional_status);
  }
  return r.error.message();
}

std::string hex(Bytes b) {
  std::string s;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (i) s += ' ';
    s += fmt::format("{:02X}", b[i]);
  }
  return s.empty() ? "(empty)" : s;
}

}  // namespace

Node::Node(const NodeConfig& config, const ScannerConfig& port, can::FrameSink& sink,
           ScannerObserver& observer, Logger log)
    : config_(config),
      port_(port),
      sink_(sink),
      observer_(observer),
      log_(std::move(log)),
      client_(port.master_mac, config.mac, port.explicit_messaging, sink, *this),
      retry_delay_(port.allocate_retry_min),
      poll_epr_(config.expected_packet_rate),
      explicit_epr_(config.explicit_packet_rate) {}

// ---------------------------------------------------------------------------
// Life cycle

void Node::start(TimePoint now, TimePoint first_attempt) {
  started_ = true;
  shutting_down_ = false;
  retry_at_ = first_attempt;
  retry_delay_ = port_.allocate_retry_min;
  set_state(NodeState::kAbsent, "waiting for the first Allocate", now);
}

void Node::set_state(NodeState next, std::string reason, TimePoint now) {
  // A fault state stays while the periodic re-check walks through the life
  // cycle again; only its outcome (online, absent, another fault) is news.
  const bool intermediate = next == NodeState::kIdentifying ||
                            next == NodeState::kConfiguring || next == NodeState::kVerifying;
  if (is_fault(state_) && intermediate) return;
  if (next == state_ && reason == reason_) return;
  const NodeState from = state_;
  state_ = next;
  reason_ = std::move(reason);
  log_.debug("{} -> {}: {}", to_string(from), to_string(next), reason_);
  observer_.on_node_state(config_.mac, from, next, reason_, now);
}

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

    case Step::kAllocate: {
      if (r.ok()) {
        // The device is ours from here on: a fault below releases it.
        connected_ = true;
        auto format = decode_allocate_response_data(r.data.view());
        if (!format) {
          enter_fault(NodeState::kConfigurationFault,
                      fmt::format("Allocate response has an unsupported body format ({})",
                                  hex(r.data.view())),
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
        enter_fault(NodeState::kConfigurationFault,
                    fmt::format("Allocate refused: {}", status_text(r)), now);
        return;
      }
      // No answer: the node is absent. Retry with back-off, forever.
      if (state_ != NodeState::kAbsent) {
        set_state(NodeState::kAbsent, fmt::format("no answer to Allocate ({})", status_text(r)),
                  now);
      }
      retry_at_ = now + retry_delay_;
      retry_delay_ = std::min(retry_delay_ * 2, port_.allocate_retry_max);
      return;
    }

    case Step::kReleaseStale:
      attempt_allocate(now);
      return;

    case Step::kVendor:
    case Step::kProductType:
    case Step::kProductCode: {
      const auto value = r.ok() ? read_uint(r.data.view()) : std::nullopt;
      if (!value) {
        enter_fault(NodeState::kWrongDevice,
                    fmt::format("Identity attribute {} unreadable: {}",
                                step == Step::kVendor ? "vendor"
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
                                  identity_.vendor_id, identity_.product_type,
                                  identity_.product_code),
                      now);
          return;
        }
        get(Step::kRevision, kIdentityClass, 1, 4, now);
      }
      return;
    }

    // Revision, serial number and name are information: a device that
    // refuses them is still the expected device.
    case Step::kRevision:
      if (r.ok() && r.data.size() >= 2) {
        identity_.major_revision = r.data[0];
        identity_.minor_revision = r.data[1];
      }
      get(Step::kSerial, kIdentityClass, 1, 6, now);
      return;

    case Step::kSerial:
      // The CDN127 manual types the serial number UINT, the ODVA Identity
      // object UDINT: accept either.
      if (r.ok()) identity_.serial_number = read_uint(r.data.view()).value_or(0);
      get(Step::kName, kIdentityClass, 1, 7, now);
      return;

    case Step::kName:
      if (r.ok()) {
        if (auto name = cip::decode_short_string(r.data.view()); name) {
          identity_.product_name = std::string(*name);
        }
      }
      observer_.on_node_identity(config_.mac, identity_, now);
      set_state(NodeState::kConfiguring, "identity verified", now);
      setting_index_ = 0;
      next_setting(now);
      return;

    case Step::kReadSetting: {
      const auto& s = config_.profile.settings[setting_index_];
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

    case Step::kWriteSetting: {
      const auto& s = config_.profile.settings[setting_index_];
      if (!r.ok()) {
        enter_fault(NodeState::kConfigurationFault,
                    fmt::format("device refused {} = {}: {}", s.name, hex(Bytes(s.value)),
                                status_text(r)),
                    now);
        return;
      }
      ++setting_index_;
      next_setting(now);
      return;
    }

    case Step::kProducedPath:
    case Step::kConsumedPath: {
      if (!r.ok()) {
        const bool produced = step == Step::kProducedPath;
        enter_fault(NodeState::kConfigurationFault,
                    fmt::format("device refused the poll {} path {}: {}",
                                produced ? "produced" : "consumed",
                                hex(Bytes(produced ? config_.profile.produced_path
                                                   : config_.profile.consumed_path)),
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
      return;
    }

    case Step::kProducedSize:
    case Step::kConsumedSize:
    case Step::kFallbackProducedSize:
    case Step::kFallbackConsumedSize: {
      const auto value = r.ok() ? read_uint(r.data.view()) : std::nullopt;
      const bool produced = step == Step::kProducedSize || step == Step::kFallbackProducedSize;
      const bool fallback = step == Step::kFallbackProducedSize || step == Step::kFallbackConsumedSize;
      if (!value) {
        const auto& fb = config_.profile.size_fallback;
        if (!fallback && config_.profile.has_size_fallback) {
          // Connection 2 attributes 7/8 refused: ask where the profile says
          // the same sizes are kept.
          get(produced ? Step::kFallbackProducedSize : Step::kFallbackConsumedSize, fb.class_id,
              fb.instance_id, produced ? fb.produced_attribute : fb.consumed_attribute, now);
          return;
        }
        enter_fault(NodeState::kConfigurationFault,
                    fmt::format("cannot read the poll {} size: {}",
                                produced ? "produced" : "consumed",
                                r.ok() ? "bad size " + hex(r.data.view()) : status_text(r)),
                    now);
        return;
      }
      if (produced) {
        produced_size_ = *value;
        get(Step::kConsumedSize, kConnectionClass, kPollConnection, kAttrConsumedSize, now);
      } else {
        consumed_size_ = *value;
        check_sizes(now);
      }
      return;
    }

    case Step::kExplicitEpr:
    case Step::kPollEpr: {
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
      return;
    }

    case Step::kKeepAlive:
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
  get(Step::kProducedSize, kConnectionClass, kPollConnection, kAttrProducedSize, now);
}

void Node::check_sizes(TimePoint now) {
  const auto& p = config_.profile;
  if (*produced_size_ != p.produced_size || *consumed_size_ != p.consumed_size) {
    // Never guess which of the two is right: say both.
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("poll sizes differ: the device produces {} B and consumes {} B; the "
                            "configuration expects {} B and {} B ({})",
                            *produced_size_, *consumed_size_, p.produced_size, p.consumed_size,
                            p.format_description),
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
  set(Step::kPollEpr, kConnectionClass, kPollConnection, kAttrExpectedPacketRate, Bytes(value),
      now, std::min(port_.explicit_messaging.response_timeout, 2 * config_.expected_packet_rate));
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
  set_state(NodeState::kOnline,
            fmt::format("polled every {} ms; EPR {} ms (explicit {} ms); {} B out, {} B in",
                        std::chrono::duration_cast<milliseconds>(config_.poll_period).count(),
                        std::chrono::duration_cast<milliseconds>(poll_epr_).count(),
                        std::chrono::duration_cast<milliseconds>(explicit_epr_).count(),
                        config_.profile.consumed_size, config_.profile.produced_size),
            now);
  // Outputs set before the node came online go out with the first poll.
  send_poll(now);
}

void Node::lose(std::string reason, TimePoint now) {
  if (state_ == NodeState::kOnline) ++counters_.reconnects;
  connected_ = false;
  step_ = Step::kNone;
  client_.cancel_all(Errc::kNotConnected, now);
  poll_outstanding_ = false;
  next_poll_ = kNever;
  poll_deadline_ = kNever;
  keepalive_at_ = kNever;
  if (shutting_down_) {
    set_state(NodeState::kStopped, "stopped: " + reason, now);
    return;
  }
  set_state(NodeState::kAbsent, std::move(reason), now);
  retry_at_ = now + port_.allocate_retry_min;
  retry_delay_ = port_.allocate_retry_min;
}

void Node::enter_fault(NodeState fault, std::string reason, TimePoint now) {
  next_poll_ = kNever;
  poll_deadline_ = kNever;
  keepalive_at_ = kNever;
  poll_outstanding_ = false;
  set_state(fault, std::move(reason), now);
  retry_at_ = now + port_.fault_recheck;
  // Leave a device that is not ours to poll unowned, so that its own
  // connection timeout puts it in its safe state.
  if (connected_) release(Step::kReleaseFault, now);
}

void Node::record(NodeError::Kind kind, TimePoint now, std::uint32_t got, std::uint32_t expected) {
  last_error_.kind = kind;
  last_error_.at = now;
  last_error_.got = got;
  last_error_.expected = expected;
  last_error_.general_status = cip::GeneralStatus::kSuccess;
  last_error_.additional_status = cip::kNoAdditionalCode;
}

void Node::record_device_error(const ExplicitResult& result, TimePoint now) {
  record(NodeError::Kind::kDeviceError, now);
  last_error_.general_status = result.general_status;
  last_error_.additional_status = result.additional_status;
}

void Node::begin_shutdown(TimePoint now) {
  if (shutting_down_) return;
  shutting_down_ = true;
  retry_at_ = kNever;
  next_poll_ = kNever;
  keepalive_at_ = kNever;
  step_ = Step::kNone;
  client_.cancel_all(Errc::kStopped, now);
  if (state_ == NodeState::kOnline) {
    // Outputs to the device's own idle state first: one idle poll (after the
    // one outstanding, if any); the Release follows its answer or timeout.
    idle_ = true;
    outputs_dirty_ = true;
    if (!poll_outstanding_) send_poll(now);
    return;
  }
  if (connected_) {
    release(Step::kReleaseShutdown, now);
    return;
  }
  set_state(NodeState::kStopped, "orderly shutdown", now);
}

void Node::release_for_shutdown(TimePoint now) {
  if (step_ == Step::kReleaseShutdown || state_ == NodeState::kStopped) return;
  poll_outstanding_ = false;
  poll_deadline_ = kNever;
  release(Step::kReleaseShutdown, now);
}

void Node::halt(std::string_view reason, TimePoint now) {
  shutting_down_ = true;
  retry_at_ = kNever;
  next_poll_ = kNever;
  poll_deadline_ = kNever;
  keepalive_at_ = kNever;
  step_ = Step::kNone;
  connected_ = false;
  client_.cancel_all(Errc::kStopped, now);
  set_state(NodeState::kStopped, std::string(reason), now);
}

// ---------------------------------------------------------------------------
// Frames and time

void Node::on_explicit_frame(Bytes payload, TimePoint now) {
  const auto before = client_.counters();
  client_.on_frame(payload, now);
  const auto& after = client_.counters();
  if (after.malformed_frames == before.malformed_frames &&
      after.unexpected_frames == before.unexpected_frames) {
    return;
  }
  unsigned suppressed = 0;
  if (error_log_limit_.allow(now, suppressed)) {
    log_.warn("{} explicit frame ignored: {}{}",
              after.malformed_frames != before.malformed_frames ? "malformed" : "unexpected",
              hex(payload),
              suppressed ? fmt::format(" ({} similar suppressed)", suppressed) : std::string());
  }
}

void Node::on_duplicate_mac_request(TimePoint now) {
  // A node checks its MAC only at power-up: whatever connections the master
  // thought it had are gone.
  if (connected_ && state_ != NodeState::kStopped && !shutting_down_) {
    lose("the node restarted (duplicate MAC ID check seen)", now);
  }
}

void Node::on_timer(TimePoint now) {
  if (now >= client_.deadline()) client_.on_timer(now);
  if (now >= retry_at_ && !shutting_down_) attempt_allocate(now);
  if (state_ != NodeState::kOnline) return;

  if (poll_outstanding_ && now >= poll_deadline_) {
    poll_outstanding_ = false;
    poll_unanswered_ = true;
    poll_deadline_ = kNever;
    ++counters_.timeouts;
    record(NodeError::Kind::kPollTimeout, now);
    // The idle poll of a shutdown went unanswered: release all the same.
    if (shutting_down_) release_for_shutdown(now);
  }
  if (shutting_down_) return;
  // The device drops the connection after 4 x EPR without a poll; the master
  // drops the node after 4 x EPR without a response.
  if (now - last_response_ >= 4 * poll_epr_) {
    record(NodeError::Kind::kConnectionLost, now);
    lose(fmt::format("no poll response for {} ms (4 x EPR)",
                     std::chrono::duration_cast<milliseconds>(now - last_response_).count()),
         now);
    return;
  }
  if (now >= next_poll_) {
    next_poll_ = next_poll_slot(now + Duration(1));
    if (!poll_outstanding_) send_poll(now);
  }
  if (now >= keepalive_at_) {
    keepalive_at_ = now + explicit_epr_;
    // Any explicit traffic keeps the explicit connection alive; only an idle
    // connection needs the keep-alive request.
    if (client_.idle()) get(Step::kKeepAlive, kIdentityClass, 1, kIdentityState, now);
  }
}

TimePoint Node::deadline() const {
  TimePoint t = client_.deadline();
  if (state_ == NodeState::kOnline && poll_outstanding_) t = std::min(t, poll_deadline_);
  if (shutting_down_) return t;
  t = std::min(t, retry_at_);
  if (state_ == NodeState::kOnline) {
    t = std::min({t, next_poll_, keepalive_at_, last_response_ + 4 * poll_epr_});
  }
  return t;
}

TimePoint Node::next_poll_slot(TimePoint after) const {
  // Slots at poll_phase_ + k * period: nodes with the same period but
  // different phases never poll in the same instant.
  const Duration period = config_.poll_period;
  if (after <= poll_phase_) return poll_phase_;
  const auto k = (after - poll_phase_ + period - Duration(1)) / period;
  return poll_phase_ + k * period;
}

// ---------------------------------------------------------------------------
// Poll connection

void Node::send_poll(TimePoint now) {
  const std::uint32_t id = group2_id(config_.mac, Group2Message::kMasterIoPoll);
  const std::size_t size = config_.profile.consumed_size;
  // A zero-length poll is the idle signal; a connection that consumes nothing
  // has no idle condition and always polls empty.
  const bool idle = idle_ || size == 0;
  if (poll_unanswered_) ++counters_.retries;
  ++counters_.polls;
  if (idle) ++counters_.idle_polls;
  if (idle || size <= can::kMaxDataLength) {
    can::CanFrame frame;
    frame.id = id;
    frame.len = static_cast<std::uint8_t>(idle ? 0 : size);
    std::copy_n(outputs_.view().begin(), frame.len, frame.data.begin());
    sink_.send(frame, now);
  } else {
    for (std::size_t i = 0; i < io_fragment_count(size); ++i) {
      can::CanFrame frame;
      frame.id = id;
      auto len = io_fragment(outputs_.view(), i, MutableBytes(frame.data));
      if (!len) break;
      frame.len = static_cast<std::uint8_t>(*len);
      sink_.send(frame, now);
    }
  }
  sent_idle_ = idle;
  sent_outputs_ = outputs_;
  outputs_dirty_ = false;
  poll_outstanding_ = true;
  poll_deadline_ = now + std::min(port_.poll_response_timeout, config_.poll_period);
}

void Node::on_poll_response(Bytes payload, TimePoint now) {
  if (state_ != NodeState::kOnline) {
    // A straggler from before the node went offline, or a device polled by
    // someone else: not ours to take.
    bad_poll_response(NodeError::Kind::kPollUnexpected, static_cast<std::uint32_t>(payload.size()),
                      now);
    return;
  }
  const std::size_t size = config_.profile.produced_size;
  if (size <= can::kMaxDataLength) {
    if (payload.size() != size) {
      bad_poll_response(NodeError::Kind::kPollLength, static_cast<std::uint32_t>(payload.size()),
                        now);
      return;
    }
    accept_poll_response(payload, now);
    return;
  }
  switch (io_reassembler_.on_fragment(payload)) {
    case IoReassembler::Outcome::kIncomplete:
      return;
    case IoReassembler::Outcome::kComplete: {
      const Bytes message = io_reassembler_.message();
      if (message.size() != size) {
        bad_poll_response(NodeError::Kind::kPollLength, static_cast<std::uint32_t>(message.size()),
                          now);
        io_reassembler_.reset();
        return;
      }
      accept_poll_response(message, now);
      io_reassembler_.reset();
      return;
    }
    default:
      bad_poll_response(NodeError::Kind::kPollMalformed, static_cast<std::uint32_t>(payload.size()),
                        now);
      return;
  }
}

void Node::accept_poll_response(Bytes data, TimePoint now) {
  if (!poll_outstanding_) {
    // Late: the poll timed out, but the data is the device's and current.
    ++counters_.errors;
    record(NodeError::Kind::kPollUnexpected, now);
  }
  poll_outstanding_ = false;
  poll_unanswered_ = false;
  poll_deadline_ = kNever;
  consecutive_errors_ = 0;
  last_response_ = now;
  ++counters_.responses;
  applied_idle_ = sent_idle_;
  applied_outputs_ = sent_outputs_;
  observer_.on_poll_response(config_.mac, data, now);
  if (shutting_down_) {
    if (outputs_dirty_) {
      send_poll(now);  // the idle poll, after the one that was outstanding
    } else {
      release_for_shutdown(now);
    }
    return;
  }
  if (outputs_dirty_ && config_.immediate_poll_on_change) send_poll(now);
}

void Node::bad_poll_response(NodeError::Kind kind, std::uint32_t got, TimePoint now) {
  ++counters_.errors;
  record(kind, now, got, static_cast<std::uint32_t>(config_.profile.produced_size));
  unsigned suppressed = 0;
  if (error_log_limit_.allow(now, suppressed)) {
    log_.warn("{}{}", last_error_.describe(),
              suppressed ? fmt::format(" ({} similar suppressed)", suppressed) : std::string());
  }
  if (state_ != NodeState::kOnline) return;
  poll_outstanding_ = false;
  poll_deadline_ = kNever;
  if (++consecutive_errors_ >= port_.max_consecutive_errors) {
    lose(fmt::format("{} bad poll responses in a row: {}", consecutive_errors_,
                     last_error_.describe()),
         now);
  }
}

Status Node::set_outputs(Bytes data, TimePoint now) {
  if (data.size() != config_.profile.consumed_size) return Errc::kOutOfRange;
  const bool changed =
      idle_ || !std::equal(data.begin(), data.end(), outputs_.view().begin(), outputs_.view().end());
  outputs_.assign(data);
  idle_ = false;
  if (!changed) return {};
  outputs_dirty_ = true;
  if (state_ == NodeState::kOnline && config_.immediate_poll_on_change && !poll_outstanding_) {
    send_poll(now);
  }
  return {};
}

void Node::set_idle(bool idle, TimePoint now) {
  if (idle == idle_) return;
  idle_ = idle;
  outputs_dirty_ = true;
  if (state_ == NodeState::kOnline && config_.immediate_poll_on_change && !poll_outstanding_) {
    send_poll(now);
  }
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
