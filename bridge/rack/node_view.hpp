#pragma once
// What every kind of node in a rack shows, whatever its profile (NodeView),
// and the rules for its outputs that the configuration chooses: what the
// bridge does with them when no commander is left, after a loss, and why
// they are idle.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/scanner_events.hpp"

namespace dnbridge::rack {

// What the bridge does with a node's outputs when no live commander is left.
enum class NoCommanderPolicy : std::uint8_t {
  kIdle,             // idle polls: the device applies its own configured idle actions
  kHoldLastOutputs,  // keep polling the last commanded outputs
};

// What a node's outputs do when it is back after a loss (poll timeout,
// power cycle, bus-off, interface down, device fault).
enum class ResumePolicy : std::uint8_t {
  kFreshCommand,  // idle until a command taken after its return
  kLastCommand,   // the last command again, at once (unsafe: a pump may start
                  // on its own after a power cycle)
};

// Why a node's outputs are idle (the bridge polls idle: the device holds
// its configured idle state).
enum class IdleCause : std::uint8_t {
  kNoCommandYet,     // nothing commanded since the bridge started
  kNoCommander,      // the last commander went away
  kAfterLoss,        // back after a loss: a new command is needed (ResumePolicy::kFreshCommand)
  kReconfigured,     // configured again after a reload: a new command is needed
  kCommanderSilent,  // the command was not written again within the node's command refresh
};
std::string_view to_string(IdleCause cause) noexcept;

// The part of a node's view every profile has.
struct NodeView {
  std::string_view profile;  // the node's profile's name (ProfileNodes::profile)
  devicenet::MacId mac;
  std::string name;
  bool online = false;
  devicenet::NodeState state = devicenet::NodeState::kAbsent;
  std::string reason;
  TimePoint state_since{};

  // Inputs from the last poll response are in the profile's view (valid
  // once `has_inputs`).
  bool has_inputs = false;
  // The device answers idle polls without data: while idle its inputs are
  // not known (has_inputs is false), rather than shown as they last were.
  bool inputs_withheld_when_idle = false;
  TimePoint inputs_time{};  // CAN receive time of that response

  // The device applied idle outputs with its last answered poll.
  bool outputs_idle = true;
  // Who asked for the outputs requested (the profile's view has them).
  std::string commanded_by;
  // Why the outputs are idle, when no command is in force.
  IdleCause idle_cause = IdleCause::kNoCommandYet;
  // Zero: off. Otherwise a command not written again for this long is no
  // longer in force (IdleCause::kCommanderSilent).
  Duration command_refresh{};
  // IdleCause::kCommanderSilent: how long the commander had been silent
  // when its command lapsed (its refresh).
  Duration silent_for{};
  // "idle: ..." when no command is in force; empty otherwise.
  std::string idle_text(bool command_in_force) const;
  // The device's minor faults (Identity.Status), in words; empty when none.
  std::string minor_faults;

  std::uint64_t commands_accepted = 0;
  std::uint64_t commands_refused = 0;
  std::string last_command_refused;  // why the last refused command was refused

  devicenet::NodeIdentity identity;
  std::optional<std::uint8_t> device_state;
  std::uint64_t changes = 0;         // bumped on every change, for publishers
  std::uint64_t status_changes = 0;  // bumped on changes of state, identity,
                                     // device state and command refusals only
};

}  // namespace dnbridge::rack
