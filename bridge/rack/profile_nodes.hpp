#pragma once
// A port's nodes of one profile, as everything above the rack sees them
// whatever the profile: a command goes to the node at a MAC, a release
// idles it, a silent commander's command lapses, a view says what the node
// is doing. NodeRack<Profile> is the one implementation (node_rack.hpp);
// each profile's rack (PumpRack, DeviceRack) adds the forms of command its
// profile takes. A command travels to it as a NodeCommand, which names no
// profile, so that what carries it (the DDS input, the port loop's inbox)
// is one path for all of them.
#include <any>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bridge/common/result.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/scanner_events.hpp"
#include "bridge/rack/node_view.hpp"

namespace dnbridge::devicenet {
class Scanner;
}  // namespace dnbridge::devicenet

namespace dnbridge::rack {

// A command's outputs in one of the forms a profile takes (a CDN127's
// PumpOutputs; an EDS device's bytes or its fields), held without naming
// the profile. The node's rack takes the forms it knows and refuses others.
class NodeCommand {
 public:
  template <class Outputs>
  explicit NodeCommand(Outputs outputs) : outputs_(std::move(outputs)) {}
  // The outputs when they are in the form `Outputs`; null otherwise.
  template <class Outputs>
  const Outputs* as() const noexcept {
    return std::any_cast<Outputs>(&outputs_);
  }

 private:
  std::any outputs_;
};

struct PublishPolicy;
class StateGate;

class ProfileNodes : public devicenet::ScannerObserver {
 public:
  // The profile's name as the rack file gives it ("cdn127", "eds"), in
  // static storage: readers keep the view for the life of the program.
  virtual std::string_view profile() const noexcept = 0;

  // The master these nodes are on, once it is built (it reports to them).
  virtual void attach(devicenet::Scanner& scanner) = 0;
  // The node at `mac` leaves the scan list (nothing when not one of these).
  virtual void remove(devicenet::MacId mac) = 0;

  // The node at `mac` when it is one of these; null otherwise.
  virtual const NodeView* node(devicenet::MacId mac) const = 0;
  // The nodes, in the order of the configuration.
  virtual std::size_t size() const = 0;
  virtual const NodeView& view(std::size_t i) const = 0;

  // New outputs for the node at `mac`: checked by the profile, then handed
  // to the master. Refused (counted, the reason kept in the view) when not
  // acceptable, or in a form this profile does not take; kOutOfRange for a
  // MAC that is not one of these nodes.
  virtual Status command(devicenet::MacId mac, const NodeCommand& command, std::string_view issuer,
                         TimePoint now) = 0;
  // No live commander left: the node goes idle (zero-length polls, so the
  // device applies its own configured idle actions) or, if configured so,
  // keeps its last outputs.
  virtual Status release_command(devicenet::MacId mac, TimePoint now) = 0;

  // The command refresh: a command in force on an online node that was not
  // written again by its lapse time counts as having no live commander
  // (release_command, with IdleCause::kCommanderSilent). Returns the nodes
  // released so, with the issuer that fell silent and how long it had been.
  struct Silenced {
    devicenet::MacId mac;
    std::string issuer;
    Duration silent_for{};
    bool outputs_held = false;  // NoCommanderPolicy::kHoldLastOutputs kept them
  };
  virtual std::vector<Silenced> expire_silent_commanders(TimePoint now) = 0;
  // When expire_silent_commanders has next something to do; kNever if not.
  virtual TimePoint next_refresh_deadline() const = 0;

  // The nodes whose view may have changed (NodeView::changes or
  // status_changes) since the last call, a bit per MAC, and none from then
  // on: a publisher looks again at these nodes only, and at the others when
  // a period of theirs is due.
  virtual std::uint64_t take_changed() noexcept = 0;

  // When one of these nodes' state is worth a new sample (publish_gate.hpp).
  virtual std::unique_ptr<StateGate> state_gate(const PublishPolicy& policy) const = 0;
};

}  // namespace dnbridge::rack
