#include "bridge/devicenet/master/bus_probe.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <optional>

#include "bridge/cip/data_types.hpp"
#include "bridge/cip/objects.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/devicenet/master/node_internal.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"

namespace dnbridge::devicenet {

using node_detail::read_uint;
using node_detail::status_text;

namespace {

namespace ident = cip::identity;

// What a probe asks, in order, once the explicit connection is allocated.
constexpr std::array<cip::AttributeRef, 6> kIdentityReads{
    ident::kVendorId, ident::kProductType,  ident::kProductCode,
    ident::kRevision, ident::kSerialNumber, ident::kProductName};

RequestMessage connection_request(cip::Service service, Bytes data) {
  RequestMessage m;
  m.service = static_cast<std::uint8_t>(service);
  m.class_id = kDeviceNetClass;
  m.instance_id = 1;
  m.data = data;
  return m;
}

}  // namespace

// One MAC being asked: its own explicit client, one request at a time.
class BusProbe::Slot final : private ExplicitClient::Listener {
 public:
  Slot(can::FrameSink& sink, MacId master, MacId mac, Config config)
      : client_(master, mac, ExplicitClient::Config{config.response_timeout, {}}, sink, *this),
        allocate_timeout_(config.allocate_timeout),
        allocate_data_{allocation::kExplicit, master.value()} {
    finding_.mac = mac;
  }

  MacId mac() const { return finding_.mac; }
  bool done() const { return done_; }
  ExplicitClient& client() { return client_; }
  ScanFinding take() { return std::move(finding_); }

  void start(TimePoint now) {
    step_ = kAllocate;
    submit(connection_request(cip::Service::kAllocateMasterSlave, Bytes(allocate_data_)), true, now,
           allocate_timeout_);
  }

  void cancel(std::string_view why, TimePoint now) {
    if (done_) return;
    finding_.outcome = ScanOutcome::kNotAsked;
    finding_.identity = {};
    finding_.detail = std::string(why);
    done_ = true;
    client_.cancel_all(Errc::kStopped, now);
  }

 private:
  static constexpr int kAllocate = -1;
  static constexpr int kRelease = static_cast<int>(kIdentityReads.size());

  void submit(const RequestMessage& m, bool unconnected, TimePoint now,
              std::optional<Duration> timeout = std::nullopt) {
    if (!client_.submit(0, m, unconnected, now, timeout)) {
      // Cannot happen with one request at a time; reported rather than hung.
      end(ScanOutcome::kRefused, "request could not be queued");
    }
  }

  void end(ScanOutcome outcome, const std::string& detail) {
    if (done_) return;
    finding_.outcome = outcome;
    // An identity only whole: what was read of one refused in part is not
    // enough to configure the device by (the detail says what was refused).
    if (outcome != ScanOutcome::kIdentified) finding_.identity = {};
    if (!detail.empty()) note(detail);
    done_ = true;
  }

  void note(const std::string& what) {
    if (!finding_.detail.empty()) finding_.detail += "; ";
    finding_.detail += what;
  }

  void on_explicit_result(ExplicitClient::Tag, const ExplicitResult& r, TimePoint now) override {
    if (done_) return;  // cancelled
    if (step_ == kAllocate) {
      after_allocate(r, now);
    } else if (step_ == kRelease) {
      if (!r.ok()) note("Release refused: " + status_text(r));
      // What a configuration needs of the device: who made it and what it is.
      end(identity_read_ ? ScanOutcome::kIdentified : ScanOutcome::kRefused, "");
    } else {
      after_read(r);
      next(now);
    }
  }

  void after_allocate(const ExplicitResult& r, TimePoint now) {
    if (r.error == Errc::kTimeout) {
      end(ScanOutcome::kNoAnswer, "");
      return;
    }
    if (r.error == Errc::kDeviceError &&
        r.general_status == cip::GeneralStatus::kObjectStateConflict &&
        r.additional_status == 0x01) {
      end(ScanOutcome::kOwnedByOtherMaster,
          "Allocate refused: owned by another master (0x0C/0x01)");
      return;
    }
    if (!r.ok()) {
      end(ScanOutcome::kRefused, "Allocate refused: " + status_text(r));
      return;
    }
    const auto format = decode_allocate_response_data(r.data.view());
    if (!format) {
      // Nothing more can be asked in a format not known; what was allocated
      // is released all the same.
      note(fmt::format("Allocate response has an unsupported body format ({})",
                       node_detail::hex(r.data.view())));
      step_ = kRelease - 1;
      next(now);
      return;
    }
    client_.set_body_format(*format);
    step_ = kAllocate;
    next(now);
  }

  void after_read(const ExplicitResult& r) {
    const cip::AttributeRef& target = kIdentityReads[static_cast<std::size_t>(step_)];
    if (!r.ok()) {
      note(fmt::format("{} refused: {}", target.name, status_text(r)));
      return;
    }
    NodeIdentity& id = finding_.identity;
    const Bytes data = r.data.view();
    switch (target.attribute) {
      case cip::identity_attr::kRevision:
        if (data.size() >= 2) {
          id.major_revision = data[0];
          id.minor_revision = data[1];
          return;
        }
        break;
      case cip::identity_attr::kProductName:
        if (auto name = cip::decode_short_string(data)) {
          id.product_name = std::string(*name);
          return;
        }
        break;
      default:
        if (auto value = read_uint(data)) {
          if (target.attribute == cip::identity_attr::kVendor) {
            id.vendor_id = static_cast<std::uint16_t>(*value);
            vendor_read_ = true;
          }
          if (target.attribute == cip::identity_attr::kProductType) {
            id.product_type = static_cast<std::uint16_t>(*value);
            type_read_ = true;
          }
          if (target.attribute == cip::identity_attr::kProductCode) {
            id.product_code = static_cast<std::uint16_t>(*value);
            identity_read_ = vendor_read_ && type_read_;
          }
          // The CDN127 manual types the serial number UINT, the ODVA
          // Identity object UDINT: either is taken.
          if (target.attribute == cip::identity_attr::kSerialNumber) id.serial_number = *value;
          return;
        }
        break;
    }
    note(fmt::format("{} unreadable: {}", target.name, node_detail::hex(data)));
  }

  void next(TimePoint now) {
    ++step_;
    if (step_ == kRelease) {
      const std::array<std::uint8_t, 1> choice{allocation::kExplicit};
      release_data_ = choice;
      submit(connection_request(cip::Service::kReleaseMasterSlave, Bytes(release_data_)), true,
             now);
      return;
    }
    const cip::AttributeRef& target = kIdentityReads[static_cast<std::size_t>(step_)];
    RequestMessage m;
    m.service = cip::code(cip::Service::kGetAttributeSingle);
    m.class_id = target.class_id;
    m.instance_id = target.instance_id;
    m.attribute = target.attribute;
    submit(m, false, now);
  }

  ExplicitClient client_;
  Duration allocate_timeout_;
  std::array<std::uint8_t, 2> allocate_data_;
  bool vendor_read_ = false;
  bool type_read_ = false;
  bool identity_read_ = false;  // vendor, product type and product code
  std::array<std::uint8_t, 1> release_data_{};
  int step_ = kAllocate;
  bool done_ = false;
  ScanFinding finding_;
};

BusProbe::BusProbe(MacId master, std::vector<MacId> probe,
                   const std::vector<MacId>& answering_other_master, Config config,
                   can::FrameSink& sink)
    : master_(master), waiting_(std::move(probe)), config_(config), sink_(sink) {
  std::reverse(waiting_.begin(), waiting_.end());
  for (MacId mac : answering_other_master) {
    findings_.push_back({mac,
                         ScanOutcome::kAnsweringOtherMaster,
                         {},
                         "heard answering another master's polls: not asked"});
  }
}

BusProbe::~BusProbe() = default;

void BusProbe::start(TimePoint now) { fill_slots(now); }

void BusProbe::fill_slots(TimePoint now) {
  // Finished slots give their finding and make room for the next MACs.
  for (auto it = slots_.begin(); it != slots_.end();) {
    if ((*it)->done()) {
      finished((*it)->take());
      it = slots_.erase(it);
    } else {
      ++it;
    }
  }
  while (slots_.size() < kSlots && !waiting_.empty()) {
    const MacId mac = waiting_.back();
    waiting_.pop_back();
    slots_.push_back(std::make_unique<Slot>(sink_, master_, mac, config_));
    slots_.back()->start(now);
    if (slots_.back()->done()) {
      finished(slots_.back()->take());
      slots_.pop_back();
    }
  }
}

void BusProbe::finished(ScanFinding finding) {
  const auto at = std::upper_bound(findings_.begin(), findings_.end(), finding.mac,
                                   [](MacId mac, const ScanFinding& f) { return mac < f.mac; });
  findings_.insert(at, std::move(finding));
}

bool BusProbe::on_frame(MacId mac, Bytes payload, TimePoint now) {
  for (auto& slot : slots_) {
    if (slot->mac() != mac || slot->done()) continue;
    slot->client().on_frame(payload, now);
    fill_slots(now);
    return true;
  }
  return false;
}

void BusProbe::on_timer(TimePoint now) {
  for (auto& slot : slots_) {
    if (!slot->done() && now >= slot->client().deadline()) slot->client().on_timer(now);
  }
  fill_slots(now);
}

TimePoint BusProbe::deadline() const {
  TimePoint next = kNever;
  for (const auto& slot : slots_) {
    if (!slot->done()) next = std::min(next, slot->client().deadline());
  }
  return next;
}

bool BusProbe::done() const { return slots_.empty() && waiting_.empty(); }

void BusProbe::cancel(std::string_view why, TimePoint now) {
  for (auto& slot : slots_) slot->cancel(why, now);
  while (!waiting_.empty()) {
    finished({waiting_.back(), ScanOutcome::kNotAsked, {}, std::string(why)});
    waiting_.pop_back();
  }
  fill_slots(now);
}

}  // namespace dnbridge::devicenet
