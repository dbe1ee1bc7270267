#pragma once
// What every kind of node in a rack shares, whatever its profile: the
// master's events turned into a view (life cycle, identity, device state,
// inputs and applied outputs), and the rules for its outputs: commanded
// only while online, idle when the last commander goes (or held, if so
// configured), void after a loss (unless configured otherwise) and after a
// device fault always, refused with the reason kept.
//
// NodeRack<Profile> is that logic once; a profile says what its data is:
//
//   struct Profile {
//     static constexpr std::string_view kName = ...;  // as the rack file names it
//     using Config = ...;   // .node (devicenet::NodeConfig), .no_commander, .resume,
//                           // .command_refresh
//     using View = ...;     // derives from NodeView; .outputs_requested (std::optional<Outputs>)
//     using Outputs = ...;  // a command's outputs, as the layer above gives them
//     struct Slot;          // what the profile keeps per node (its data layout)
//     static Slot slot_of(const Config&);               // throws std::invalid_argument
//     static View view_of(const Config&, const Slot&);
//     static void carry_over(const View& old, View& fresh);  // counters kept on a reconfiguration
//     static void on_online(View&, const Slot&, const devicenet::Node&);
//     static bool take_inputs(View&, const Slot&, Bytes data);  // false: not decodable
//     static void take_applied(View&, const Slot&, Bytes outputs);
//   };
//
// PumpRack (the CDN127) and DeviceRack (nodes described by their EDS) are
// its two profiles; each adds the command forms its profile takes and the
// ProfileNodes::command that picks them from a NodeCommand.
#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/rack/node_view.hpp"
#include "bridge/rack/profile_nodes.hpp"

namespace dnbridge::rack {

template <class Profile>
class NodeRack : public ProfileNodes {
 public:
  using Config = typename Profile::Config;
  using View = typename Profile::View;
  using Outputs = typename Profile::Outputs;
  using Slot = typename Profile::Slot;

  explicit NodeRack(const std::vector<Config>& nodes) {
    index_.fill(-1);
    for (const auto& n : nodes) add(n);
  }

  // Attach after the scanner is built (the scanner reports to this rack).
  // A rack that comes after the master started (a reload's new profile)
  // takes the port's state as it is.
  void attach(devicenet::Scanner& scanner) override {
    scanner_ = &scanner;
    port_state_ = scanner.state();
    port_reason_ = scanner.reason();
  }

  // What the bridge itself does with the node is the same: its name, its
  // no-commander and resume policies, its command refresh.
  static bool same_handling(const Config& a, const Config& b) {
    return a.node.name == b.node.name && a.no_commander == b.no_commander && a.resume == b.resume &&
           a.command_refresh == b.command_refresh;
  }

  std::string_view profile() const noexcept override { return Profile::kName; }

  Status release_command(devicenet::MacId mac, TimePoint now) override {
    return release(mac, IdleCause::kNoCommander, now);
  }

  // A command lapses at its lapse time: the node's command_refresh after it
  // was taken.
  std::vector<Silenced> expire_silent_commanders(TimePoint now) override {
    std::vector<Silenced> out;
    for (std::size_t i = 0; i < views_.size(); ++i) {
      const Entry& e = entries_[i];
      if (!lapse_due(views_[i], e) || now < e.lapse_at) continue;
      // Silent for at least its refresh (the loop may see it a little late).
      Silenced s{views_[i].mac, views_[i].commanded_by, e.lapse_at - e.last_command};
      views_[i].silent_for = s.silent_for;
      mark_changed(s.mac);
      (void)release(s.mac, IdleCause::kCommanderSilent, now);
      s.outputs_held = views_[i].outputs_requested.has_value();
      out.push_back(std::move(s));
    }
    return out;
  }
  TimePoint next_refresh_deadline() const override {
    TimePoint next = kNever;
    for (std::size_t i = 0; i < views_.size(); ++i) {
      if (lapse_due(views_[i], entries_[i])) next = std::min(next, entries_[i].lapse_at);
    }
    return next;
  }

  std::uint64_t take_changed() noexcept override { return std::exchange(changed_, 0); }

  // Live changes, made together with the master's scan list
  // (RackPort::reconfigure). A new node's view is absent, with no command.
  void add(const Config& c) {
    if (index_[c.node.mac.value()] >= 0) {
      throw std::invalid_argument("node " + std::to_string(c.node.mac.value()) +
                                  " is in the rack twice");
    }
    entries_.push_back(entry_of(c));
    index_[c.node.mac.value()] = static_cast<int>(views_.size());
    views_.push_back(Profile::view_of(c, entries_.back().slot));
    views_.back().profile = Profile::kName;
    views_.back().command_refresh = c.command_refresh;
    mark_changed(c.node.mac);
  }
  void remove(devicenet::MacId mac) override {
    const int i = index_[mac.value()];
    if (i < 0) return;
    views_.erase(views_.begin() + i);
    entries_.erase(entries_.begin() + i);
    index_.fill(-1);
    for (std::size_t k = 0; k < views_.size(); ++k) {
      index_[views_[k].mac.value()] = static_cast<int>(k);
    }
  }
  // The node's device settings changed: the master releases it and
  // configures it again, so its view starts afresh, in its place, and no
  // command survives.
  void replace(const Config& c) {
    const int i = index_[c.node.mac.value()];
    if (i < 0) return add(c);
    const auto index = static_cast<std::size_t>(i);
    entries_[index] = entry_of(c);
    View& v = views_[index];
    // Its counters go on (they are the node's, whatever its settings); the
    // rest starts again.
    View fresh = Profile::view_of(c, entries_[index].slot);
    fresh.profile = Profile::kName;
    fresh.commands_accepted = v.commands_accepted;
    fresh.commands_refused = v.commands_refused;
    Profile::carry_over(v, fresh);
    fresh.reason = "configuration changed: released, to be configured again";
    fresh.state_since = v.state_since;
    fresh.idle_cause = IdleCause::kReconfigured;
    fresh.command_refresh = c.command_refresh;
    fresh.changes = v.changes + 1;
    fresh.status_changes = v.status_changes + 1;
    v = std::move(fresh);
    mark_changed(c.node.mac);
  }
  // Only what the bridge itself does with the node changed (its name, its
  // no-commander and resume policies, its command refresh): view and command
  // are kept, but for outputs held for a commander that has gone when the
  // new policy is idle. A command in force under a refresh that changes must
  // still be written again in time: by its lapse time under the refresh it
  // was taken with (when the new one is off), or within the new refresh
  // from now, whichever is later.
  void update(const Config& c, TimePoint now) {
    View* v = find(c.node.mac);
    if (!v) return;
    Entry& e = entry(c.node.mac);
    e.no_commander = c.no_commander;
    e.resume = c.resume;
    if (v->command_refresh != c.command_refresh && v->outputs_requested) {
      const bool was_on = v->command_refresh > Duration::zero();
      if (c.command_refresh > Duration::zero()) {
        e.lapse_at = std::max(was_on ? e.lapse_at : TimePoint{}, now + c.command_refresh);
      } else if (!was_on) {
        e.lapse_at = kNever;
      }
    }
    mark_changed(c.node.mac);
    v->command_refresh = c.command_refresh;
    v->name = c.node.name;
    ++v->changes;
    ++v->status_changes;
    if (e.held_without_commander && c.no_commander == NoCommanderPolicy::kIdle) {
      (void)release_command(c.node.mac, now);
    }
  }

  const std::vector<View>& nodes() const { return views_; }
  const View* node(devicenet::MacId mac) const override {
    const int i = index_[mac.value()];
    return i < 0 ? nullptr : &views_[static_cast<std::size_t>(i)];
  }
  std::size_t size() const override { return views_.size(); }
  const View& view(std::size_t i) const override { return views_[i]; }
  devicenet::PortState port_state() const { return port_state_; }
  const std::string& port_reason() const { return port_reason_; }

  // ScannerObserver
  void on_port_state(devicenet::PortState state, const std::string& reason, TimePoint) override {
    port_state_ = state;
    port_reason_ = reason;
  }
  void on_node_state(devicenet::MacId mac, devicenet::NodeState from, devicenet::NodeState to,
                     const std::string& reason, TimePoint at) override {
    using devicenet::NodeState;
    View* v = find(mac);
    if (!v) return;
    mark_changed(mac);
    // A device fault voids a command even before the node was first online:
    // the fault may clear long after the command was given.
    if ((from == NodeState::kOnline && to != NodeState::kOnline && to != NodeState::kStopped) ||
        to == NodeState::kDeviceFault) {
      on_loss(*v, entry(mac), to, at);
    }
    if (to == NodeState::kOnline && scanner_ != nullptr) {
      if (const devicenet::Node* node = scanner_->node(mac)) {
        Profile::on_online(*v, entry(mac).slot, *node);
      }
    }
    if (to == NodeState::kOnline && v->outputs_requested && v->command_refresh > Duration::zero()) {
      entry(mac).lapse_at = at + v->command_refresh;
    }
    v->state = to;
    v->reason = reason;
    v->state_since = at;
    v->online = to == NodeState::kOnline;
    v->has_inputs = false;  // until a poll response since this transition
    v->inputs_withheld_when_idle = false;
    ++v->changes;
    ++v->status_changes;
  }
  void on_node_identity(devicenet::MacId mac, const devicenet::NodeIdentity& identity,
                        TimePoint) override {
    if (View* v = find(mac)) {
      mark_changed(mac);
      v->identity = identity;
      const devicenet::Node* node = scanner_ ? scanner_->node(mac) : nullptr;
      v->minor_faults = node ? node->minor_faults() : "";
      ++v->changes;
      ++v->status_changes;
    }
  }
  void on_poll_response(devicenet::MacId mac, Bytes data, TimePoint rx_time) override {
    View* v = find(mac);
    if (!v) return;
    mark_changed(mac);
    const Slot& slot = entry(mac).slot;
    if (data.empty()) {
      // An idle poll answered with no data: the device applied its idle
      // outputs, and said nothing of its inputs. What they last were is not
      // what they are: no inputs are published until a response carries them.
      if (v->has_inputs || !v->inputs_withheld_when_idle) ++v->status_changes;
      v->has_inputs = false;
      v->inputs_withheld_when_idle = true;
      refresh_applied(*v, slot);
      ++v->changes;
      return;
    }
    if (v->inputs_withheld_when_idle) ++v->status_changes;
    v->inputs_withheld_when_idle = false;
    if (!Profile::take_inputs(*v, slot, data)) return;  // the master checked the size
    v->has_inputs = true;
    v->inputs_time = rx_time;
    refresh_applied(*v, slot);
    ++v->changes;
  }
  void on_device_state(devicenet::MacId mac, std::uint8_t state, TimePoint) override {
    if (View* v = find(mac)) {
      mark_changed(mac);
      v->device_state = state;
      ++v->changes;
      ++v->status_changes;
    }
  }

 protected:
  // Two scan-list entries as configured, but for the node's name.
  static bool same_scan_entry(devicenet::NodeConfig a, devicenet::NodeConfig b) {
    a.name.clear();
    b.name.clear();
    return a == b;
  }

  View* find(devicenet::MacId mac) {
    const int i = index_[mac.value()];
    return i < 0 ? nullptr : &views_[static_cast<std::size_t>(i)];
  }
  const Slot& slot(devicenet::MacId mac) const {
    return entries_[static_cast<std::size_t>(index_[mac.value()])].slot;
  }
  devicenet::Scanner* scanner() { return scanner_; }

  // Every change to a node's view marks it (take_changed), whether or not
  // its counters moved: a publisher that looks once too often loses nothing.
  void mark_changed(devicenet::MacId mac) noexcept { changed_ |= std::uint64_t{1} << mac.value(); }

  // A refusal: counted, its reason kept in the view.
  Status refuse(View& view, Status why, std::string&& text) {
    mark_changed(view.mac);
    ++view.commands_refused;
    view.last_command_refused = std::move(text);
    ++view.changes;
    ++view.status_changes;
    return why;
  }

  // A command in a form the profile does not take (one meant for another
  // profile's node): refused, counted.
  Status refuse_other_form(devicenet::MacId mac, std::string_view issuer) {
    View* v = find(mac);
    if (!v) return Errc::kOutOfRange;
    return refuse(*v, Errc::kUnsupported,
                  "from " + std::string(issuer) + ": not a command for a node of profile \"" +
                      std::string(Profile::kName) + "\"");
  }

  // Only an online node is commanded: a command kept for a node that is
  // away would act whenever it comes (back), perhaps hours later. A refusal
  // (counted) when it is not; nothing otherwise.
  Status refuse_unless_online(View& v, std::string_view issuer) {
    if (v.online) return {};
    return refuse(v, Errc::kNotConnected,
                  v.idle_cause == IdleCause::kAfterLoss
                      ? "from " + std::string(issuer) +
                            ": the node was lost and is not back online; only a command "
                            "written after its return is applied"
                      : "from " + std::string(issuer) + ": the node is not online (" +
                            std::string(devicenet::to_string(v.state)) +
                            "); a command applies only to an online node");
  }

  // Hands `data` (the poll request's bytes for `outputs`) to the master and
  // records the command; a refusal if the master does not take it.
  Status apply_command(View& v, Bytes data, const Outputs& outputs, std::string_view issuer,
                       TimePoint now) {
    if (auto s = scanner_->set_outputs(v.mac, data, now); !s) {
      return refuse(v, s, "from " + std::string(issuer) + ": " + s.error().message());
    }
    v.outputs_requested = outputs;
    v.commanded_by = std::string(issuer);
    Entry& e = entry(v.mac);
    e.held_without_commander = false;
    e.last_command = now;
    e.lapse_at = v.command_refresh > Duration::zero() ? now + v.command_refresh : kNever;
    ++v.commands_accepted;
    ++v.changes;
    mark_changed(v.mac);
    return {};
  }

 private:
  struct Entry {
    Slot slot;
    NoCommanderPolicy no_commander = NoCommanderPolicy::kIdle;
    ResumePolicy resume = ResumePolicy::kFreshCommand;
    // The last commander went away while the policy held its outputs.
    bool held_without_commander = false;
    TimePoint last_command{};     // when the command in force was last taken
    TimePoint lapse_at = kNever;  // when it lapses unless written again
  };
  static Entry entry_of(const Config& c) {
    return Entry{Profile::slot_of(c), c.no_commander, c.resume, false, {}, kNever};
  }

  // A command is in force on an online node, and may lapse. (Offline, a
  // command is neither renewed nor applied; one kept by resume =
  // "last-command" gets a refresh from the node's return.)
  static bool lapse_due(const View& v, const Entry& e) {
    return v.online && v.outputs_requested.has_value() && !e.held_without_commander &&
           e.lapse_at != kNever;
  }

  // No live commander left (`cause`): idle, or the outputs held if the
  // node's policy says so.
  Status release(devicenet::MacId mac, IdleCause cause, TimePoint now) {
    View* v = find(mac);
    if (!v || !scanner_) return Errc::kOutOfRange;
    Entry& e = entry(mac);
    if (e.no_commander == NoCommanderPolicy::kHoldLastOutputs) {
      e.held_without_commander = v->outputs_requested.has_value();
      return {};
    }
    e.held_without_commander = false;
    if (v->outputs_requested) v->idle_cause = cause;
    v->outputs_requested.reset();
    v->commanded_by.clear();
    ++v->changes;
    mark_changed(mac);
    return scanner_->set_idle(mac, true, now);
  }
  Entry& entry(devicenet::MacId mac) {
    return entries_[static_cast<std::size_t>(index_[mac.value()])];
  }

  // The node left online, or has a device fault: with kFreshCommand (and
  // for a device fault always) its command is void, and it comes back idle.
  void on_loss(View& v, const Entry& e, devicenet::NodeState to, TimePoint at) {
    // A device fault voids the command whatever the policy: the fault (a loss
    // of the outputs' supply) may clear long after.
    if (e.resume == ResumePolicy::kLastCommand && to != devicenet::NodeState::kDeviceFault) {
      return;
    }
    // The last command was for the device as it was before: after a power
    // cycle, a cable or a bus-off nobody has seen its state since. Idle polls
    // until a commander, having seen it back, commands it again.
    v.idle_cause = IdleCause::kAfterLoss;
    v.outputs_requested.reset();
    v.commanded_by.clear();
    if (scanner_) (void)scanner_->set_idle(v.mac, true, at);
  }

  void refresh_applied(View& v, const Slot& slot) {
    const devicenet::Node* node = scanner_ ? scanner_->node(v.mac) : nullptr;
    if (!node) return;
    v.outputs_idle = node->applied_idle();
    if (!v.outputs_idle) Profile::take_applied(v, slot, node->applied_outputs());
  }

  devicenet::Scanner* scanner_ = nullptr;
  std::uint64_t changed_ = 0;  // take_changed's, a bit per MAC
  std::vector<View> views_;
  std::vector<Entry> entries_;
  std::array<int, devicenet::MacId::kMax + 1> index_{};
  devicenet::PortState port_state_ = devicenet::PortState::kStopped;
  std::string port_reason_;
};

}  // namespace dnbridge::rack
