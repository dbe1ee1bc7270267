#pragma once
// The control language of cdn127-sim: one command per line, from its
// standard input or a control FIFO, each answered with one line ("ok ...",
// or "error: ..."). Pure: parsing only.
//
//   set MAC alarm on|off          pump alarm ("Pump Fail"): the pump stops
//   set MAC warning on|off
//   set MAC n2-flow on|off        N2 purge flow present (on = ok)
//   set MAC interlock on|off      interlock satisfied (on = ok)
//   set MAC ain1|ain2 VALUE       analog input: volts with a V ("2.5V",
//                                 0..10) or raw counts (0..4095)
//   set MAC param N VALUE         a device driven by its EDS: its ParamN (an
//                                 input, as the device's own process sets
//                                 it), then a change-of-state message if due
//   fault MAC|all FAULT on|off    an Identity fault (attribute 5 bits 8..11):
//                                 minor-recoverable, minor-unrecoverable,
//                                 major-recoverable (State 4) or
//                                 major-unrecoverable (State 5); a major
//                                 one applies the fault actions and holds
//                                 the outputs there until cleared
//   power-cycle MAC|all           off and on again: volatile state lost,
//                                 duplicate MAC check, waits for a master;
//                                 E2 kept; unrecoverable faults end
//   power-off MAC|all             silent and deaf until power-on
//   power-on MAC|all              after power-off: a power cycle, as above
//   status [MAC]                  one line per device (Identity state and
//                                 faults at its end)
//   help
//   quit                          ends cdn127-sim (so does end of input)
//
// "Pump running" is an input the pump drives: it follows the Pump On output
// the master sets, after the pump's spin-up time, and drops with an alarm or
// an open interlock.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

namespace dnbridge::sim::host {

enum class Verb : std::uint8_t {
  kSet,
  kFault,
  kPowerCycle,
  kPowerOff,
  kPowerOn,
  kStatus,
  kHelp,
  kQuit
};
enum class Input : std::uint8_t {
  kAlarm,
  kWarning,
  kN2Flow,
  kInterlock,
  kAnalog1,
  kAnalog2,
  kParam,  // an EDS-driven device's ParamN
};
// The Identity faults (sim::IdentityFaults).
enum class Fault : std::uint8_t {
  kMinorRecoverable,
  kMinorUnrecoverable,
  kMajorRecoverable,
  kMajorUnrecoverable
};

struct ControlCommand {
  Verb verb = Verb::kHelp;
  std::optional<std::uint8_t> mac;         // none: every device
  Input input = Input::kAlarm;             // kSet
  bool on = false;                         // kSet of a digital input; kFault: set or cleared
  Fault fault = Fault::kMinorRecoverable;  // kFault
  std::uint16_t raw = 0;                   // kSet of an analog input, 12-bit counts
  unsigned param = 0;                      // kSet of kParam: N
  double value = 0;                        // kSet of kParam: the value
};

// An empty or comment line ("# ...") parses to nothing; an error is a
// message for the user.
using ParseResult = std::variant<std::monostate, ControlCommand, std::string>;
ParseResult parse_control(std::string_view line);

// The help text, as `help` and --help print it.
std::string_view control_help() noexcept;

}  // namespace dnbridge::sim::host
