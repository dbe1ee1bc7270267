#pragma once
// The state of a rack's pumps as the layer above sees it: the master's events
// turned into plain values with meaning (decoded inputs, applied outputs, life
// cycle, identity, errors). The DDS face publishes from here; the demo draws
// it. Commands are checked here before they reach the master.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"
#include "bridge/profiles/cdn127/node_profile.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::rack {

// One pump's configuration in the rack: the scan-list entry and the CDN127
// I/O configuration its poll data is decoded with.
// What the bridge does with a pump when no live commander is left.
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

struct PumpConfig {
  devicenet::NodeConfig node;
  NoCommanderPolicy no_commander = NoCommanderPolicy::kIdle;
  ResumePolicy resume = ResumePolicy::kFreshCommand;
  profiles::cdn127::SafeStateConfig safe_state;
  profiles::cdn127::IoConfiguration io;
  // The identity the device must show; the CDN127's (vendor 59, product type
  // 27, product code 1888) when not given.
  std::optional<devicenet::ExpectedIdentity> identity;
};

// Why a pump's outputs are idle (the bridge polls idle: the device holds
// its configured idle state).
enum class IdleCause : std::uint8_t {
  kNoCommandYet,  // nothing commanded since the bridge started
  kNoCommander,   // the last commander went away
  kAfterLoss,     // back after a loss: a new command is needed (ResumePolicy::kFreshCommand)
  kReconfigured,  // configured again after a reload: a new command is needed
};
std::string_view to_string(IdleCause cause) noexcept;

struct PumpView {
  devicenet::MacId mac;
  std::string name;
  bool online = false;
  devicenet::NodeState state = devicenet::NodeState::kAbsent;
  std::string reason;
  TimePoint state_since{};

  // Inputs from the last poll response (valid once `has_inputs`).
  bool has_inputs = false;
  // The device answers idle polls without data: while idle its inputs are
  // not known (has_inputs is false), rather than shown as they last were.
  bool inputs_withheld_when_idle = false;
  TimePoint inputs_time{};  // CAN receive time of that response
  profiles::cdn127::PollInputs inputs;

  // Outputs the device applied with its last answered poll.
  bool outputs_idle = true;
  profiles::cdn127::PumpOutputs outputs_applied;
  // Outputs requested by the layer above (not yet necessarily applied), and
  // who asked for them.
  std::optional<profiles::cdn127::PumpOutputs> outputs_requested;
  std::string commanded_by;
  // Why the outputs are idle, when no command is in force.
  IdleCause idle_cause = IdleCause::kNoCommandYet;
  // "idle: ..." when no command is in force; empty otherwise.
  std::string_view idle_reason() const {
    return outputs_requested ? std::string_view{} : to_string(idle_cause);
  }

  // The outputs' fault and idle actions the device had when the node last
  // came online (read back after the download, or the device's own kept),
  // and where they came from.
  std::optional<profiles::cdn127::SafeState> safe_state;
  profiles::cdn127::SafeStateSource safe_state_source =
      profiles::cdn127::SafeStateSource::kConfiguration;
  std::string safe_state_text;  // in words, for the outputs the configuration has
  // The device's minor faults (Identity.Status), in words; empty when none.
  std::string minor_faults;

  std::uint64_t commands_accepted = 0;
  std::uint64_t commands_refused = 0;
  // Poll responses that carried an input out of range (its other inputs were
  // taken; PollInputs::analog_input_in_range says which channel).
  std::uint64_t responses_with_invalid_inputs = 0;
  std::string last_command_refused;  // why the last refused command was refused

  devicenet::NodeIdentity identity;
  std::optional<std::uint8_t> device_state;
  std::uint64_t changes = 0;         // bumped on every change, for publishers
  std::uint64_t status_changes = 0;  // bumped on changes of state, identity,
                                     // device state and command refusals only
};

class PumpRack final : public devicenet::ScannerObserver {
 public:
  // Builds the scan list's node profiles from the pumps' I/O configurations.
  // Throws std::invalid_argument for an invalid configuration.
  static devicenet::ScannerConfig scanner_config(devicenet::ScannerConfig port,
                                                 const std::vector<PumpConfig>& pumps);

  explicit PumpRack(const std::vector<PumpConfig>& pumps);

  // Attach after the scanner is built (the scanner reports to this rack).
  void attach(devicenet::Scanner& scanner) { scanner_ = &scanner; }

  // Validates and forwards new outputs: refused, never clipped, when out of
  // range; refused when the configuration has no room for them (e.g. an
  // analog value for a configuration without analog output); refused while
  // the node is not online (after a loss, only a command taken after its
  // return counts). A refusal is counted and its
  // reason kept in the pump's view; nothing of the command is applied.
  // kOutOfRange for a MAC not in the rack.
  Status command(devicenet::MacId mac, const profiles::cdn127::PumpOutputs& outputs,
                 std::string_view issuer, TimePoint now);
  Status command(devicenet::MacId mac, const profiles::cdn127::PumpOutputs& outputs,
                 TimePoint now) {
    return command(mac, outputs, "local", now);
  }
  // No live commander left: the node goes idle (zero-length polls, so the
  // device applies its own configured idle actions) or, if configured so,
  // keeps its last outputs.
  Status release_command(devicenet::MacId mac, TimePoint now);

  // Live changes, made together with the master's scan list
  // (RackPort::reconfigure). A new pump's view is absent, with no command.
  void add(const PumpConfig& pump);
  void remove(devicenet::MacId mac);
  // The pump's device settings changed: the master releases it and
  // configures it again, so its view starts afresh, in its place, and no
  // command survives.
  void replace(const PumpConfig& pump);
  // Only what the bridge itself does with the pump changed (its name, its
  // no-commander and resume policies): view and command are kept, but for
  // outputs held for a commander that has gone when the new policy is idle.
  void update(const PumpConfig& pump, TimePoint now);

  const std::vector<PumpView>& pumps() const { return views_; }
  const PumpView* pump(devicenet::MacId mac) const;
  devicenet::PortState port_state() const { return port_state_; }
  const std::string& port_reason() const { return port_reason_; }

  // ScannerObserver
  void on_port_state(devicenet::PortState state, const std::string& reason, TimePoint at) override;
  void on_node_state(devicenet::MacId mac, devicenet::NodeState from, devicenet::NodeState to,
                     const std::string& reason, TimePoint at) override;
  void on_node_identity(devicenet::MacId mac, const devicenet::NodeIdentity& identity,
                        TimePoint at) override;
  void on_poll_response(devicenet::MacId mac, Bytes data, TimePoint rx_time) override;
  void on_device_state(devicenet::MacId mac, std::uint8_t state, TimePoint at) override;

 private:
  struct Slot {
    profiles::cdn127::IoConfiguration io;
    profiles::cdn127::PollFormat format;
    NoCommanderPolicy no_commander = NoCommanderPolicy::kIdle;
    ResumePolicy resume = ResumePolicy::kFreshCommand;
    // The last commander went away while the policy held its outputs.
    bool held_without_commander = false;
  };
  // The node left online, or has a device fault: with kFreshCommand (and
  // for a device fault always) its command is void, and it comes back idle.
  void on_loss(PumpView& view, const Slot& slot, devicenet::NodeState to, TimePoint at);
  // The node is online: what the device's safe state is.
  void on_online(PumpView& view);
  Status refuse(PumpView& view, Status why, std::string text);
  PumpView* find(devicenet::MacId mac);
  void refresh_applied(std::size_t index);
  static Slot slot_of(const PumpConfig& pump);
  static PumpView view_of(const PumpConfig& pump);

  devicenet::Scanner* scanner_ = nullptr;
  std::vector<PumpView> views_;
  std::vector<Slot> slots_;
  std::array<int, devicenet::MacId::kMax + 1> index_{};
  devicenet::PortState port_state_ = devicenet::PortState::kStopped;
  std::string port_reason_;
};

}  // namespace dnbridge::rack
