#pragma once
// A node's explicit connection kept alive once it is online: one request
// per expected packet rate (the EPR the device returned), which reads the
// device's health, Identity.Status (fault bits) and Identity.State in turn,
// Status alone where the device has no State. Every period, busy or not:
// other requests keep the connection alive, but only this one tells a major
// fault. The device drops the connection after 4 x EPR without a request;
// the master takes it for lost after 4 x EPR without an answer.
#include "bridge/cip/objects.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::devicenet {

class KeepAlive {
 public:
  explicit KeepAlive(Duration epr) : epr_(epr) {}

  // The expected packet rate in force: the device's, once its Set answered.
  Duration epr() const { return epr_; }
  void set_epr(Duration epr) { epr_ = epr; }
  // Identity.State answered at the start-up: the keep-alive reads it in turn.
  void set_state_supported(bool supported) { state_supported_ = supported; }
  bool state_supported() const { return state_supported_; }

  // Online: the first keep-alive one EPR from `now`, the silence from `now`.
  void start(TimePoint now) {
    last_answer_ = now;
    next_ = now + epr_;
  }
  void stop() { next_ = kNever; }
  TimePoint next() const { return next_; }
  // At `now`: when one is due, the next is scheduled an EPR on, and the
  // attribute to read is returned, unless the last one is still unanswered
  // (`outstanding`: it is not doubled); nullptr otherwise.
  const cip::AttributeRef* on_timer(TimePoint now, bool outstanding) {
    if (now < next_) return nullptr;
    next_ = now + epr_;
    if (outstanding) return nullptr;
    reads_status_ = !state_supported_ || !reads_status_;
    return reads_status_ ? &cip::identity::kStatus : &cip::identity::kState;
  }
  // Which the last keep-alive read: Identity.Status, or Identity.State.
  bool reads_status() const { return reads_status_; }

  // An answer on the explicit connection, a refusal included.
  void answered(TimePoint now) { last_answer_ = now; }
  Duration silence(TimePoint now) const { return now - last_answer_; }
  // 4 x EPR without an answer: the connection is lost.
  bool lost(TimePoint now) const { return silence(now) >= 4 * epr_; }
  // The keep-alive went unanswered, the connection not yet lost: again now.
  void again(TimePoint now) { next_ = now; }

 private:
  Duration epr_;
  bool state_supported_ = true;
  bool reads_status_ = false;  // which the last keep-alive read
  TimePoint next_ = kNever;
  TimePoint last_answer_{};
};

}  // namespace dnbridge::devicenet
