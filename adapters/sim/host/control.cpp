#include "adapters/sim/host/control.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "bridge/profiles/cdn127/io_data.hpp"

namespace dnbridge::sim::host {
namespace {

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

template <class T>
std::optional<T> number(std::string_view s) {
  T v{};
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

// "all" for every device, or a MAC 0..63.
std::variant<std::optional<std::uint8_t>, std::string> target(std::string_view s, bool allow_all) {
  if (allow_all && s == "all") return std::optional<std::uint8_t>{};
  auto mac = number<unsigned>(s);
  if (!mac || *mac > 63)
    return fmt::format("\"{}\" is not a MAC ID (0..63{})", s, allow_all ? " or all" : "");
  return std::optional<std::uint8_t>(static_cast<std::uint8_t>(*mac));
}

std::optional<bool> on_off(std::string_view s) {
  if (s == "on" || s == "1" || s == "ok" || s == "true") return true;
  if (s == "off" || s == "0" || s == "fail" || s == "false") return false;
  return std::nullopt;
}

std::variant<std::uint16_t, std::string> analog(std::string_view s) {
  if (!s.empty() && (s.back() == 'V' || s.back() == 'v')) {
    // from_chars for double: GCC 11 and later.
    auto v = number<double>(s.substr(0, s.size() - 1));
    if (!v || !std::isfinite(*v)) return fmt::format("\"{}\" is not a voltage", s);
    auto raw = profiles::cdn127::volts_to_raw(*v);
    if (!raw) return fmt::format("{} is outside 0..10 V", s);
    return *raw;
  }
  auto raw = number<unsigned>(s);
  if (!raw || *raw > 4095)
    return fmt::format("\"{}\" is neither volts (\"2.5V\") nor counts 0..4095", s);
  return static_cast<std::uint16_t>(*raw);
}

}  // namespace

ParseResult parse_control(std::string_view line) {
  const auto w = words(line);
  if (w.empty() || w[0].front() == '#') return std::monostate{};
  ControlCommand c;
  const std::string_view verb = w[0];

  auto with_target = [&](Verb v, bool optional_target) -> ParseResult {
    c.verb = v;
    if (w.size() == 1 && optional_target) return c;
    if (w.size() != 2)
      return fmt::format("usage: {} {}", verb, optional_target ? "[MAC]" : "MAC|all");
    auto t = target(w[1], true);
    if (auto* e = std::get_if<std::string>(&t)) return *e;
    c.mac = std::get<std::optional<std::uint8_t>>(t);
    return c;
  };

  if (verb == "help") {
    c.verb = Verb::kHelp;
    return c;
  }
  if (verb == "quit" || verb == "exit") {
    c.verb = Verb::kQuit;
    return c;
  }
  if (verb == "status") return with_target(Verb::kStatus, true);
  if (verb == "power-cycle") return with_target(Verb::kPowerCycle, false);
  if (verb == "power-off") return with_target(Verb::kPowerOff, false);
  if (verb == "power-on") return with_target(Verb::kPowerOn, false);
  if (verb == "fault") {
    if (w.size() != 4) return std::string("usage: fault MAC|all FAULT on|off");
    c.verb = Verb::kFault;
    auto t = target(w[1], true);
    if (auto* e = std::get_if<std::string>(&t)) return *e;
    c.mac = std::get<std::optional<std::uint8_t>>(t);
    const std::string_view fault = w[2];
    if (fault == "minor-recoverable") {
      c.fault = Fault::kMinorRecoverable;
    } else if (fault == "minor-unrecoverable") {
      c.fault = Fault::kMinorUnrecoverable;
    } else if (fault == "major-recoverable") {
      c.fault = Fault::kMajorRecoverable;
    } else if (fault == "major-unrecoverable") {
      c.fault = Fault::kMajorUnrecoverable;
    } else {
      return fmt::format(
          "unknown fault \"{}\": minor-recoverable, minor-unrecoverable, major-recoverable, "
          "major-unrecoverable",
          fault);
    }
    // Only on and off: "ok" or "fail" would read backwards for a fault.
    if (w[3] != "on" && w[3] != "off") return fmt::format("\"{}\" is not on or off", w[3]);
    c.on = w[3] == "on";
    return c;
  }
  if (verb != "set") return fmt::format("unknown command \"{}\" (help lists them)", verb);

  c.verb = Verb::kSet;
  if (w.size() == 5 && w[2] == "param") {
    auto t = target(w[1], false);
    if (auto* e = std::get_if<std::string>(&t)) return *e;
    c.mac = std::get<std::optional<std::uint8_t>>(t);
    c.input = Input::kParam;
    const std::string n(w[3]);
    const std::string v(w[4]);
    char* end = nullptr;
    const unsigned long number = std::strtoul(n.c_str(), &end, 10);
    if (n.empty() || *end != '\0' || number == 0 || number > 0xFFFF) {
      return fmt::format("\"{}\" is not a parameter number (1..65535)", n);
    }
    c.param = static_cast<unsigned>(number);
    c.value = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !std::isfinite(c.value)) {
      return fmt::format("\"{}\" is not a number", v);
    }
    return c;
  }
  if (w.size() != 4) return std::string("usage: set MAC INPUT VALUE, or set MAC param N VALUE");
  auto t = target(w[1], false);
  if (auto* e = std::get_if<std::string>(&t)) return *e;
  c.mac = std::get<std::optional<std::uint8_t>>(t);
  const std::string_view input = w[2];
  if (input == "ain1" || input == "ain2") {
    c.input = input == "ain1" ? Input::kAnalog1 : Input::kAnalog2;
    auto v = analog(w[3]);
    if (auto* e = std::get_if<std::string>(&v)) return *e;
    c.raw = std::get<std::uint16_t>(v);
    return c;
  }
  if (input == "alarm") {
    c.input = Input::kAlarm;
  } else if (input == "warning") {
    c.input = Input::kWarning;
  } else if (input == "n2-flow") {
    c.input = Input::kN2Flow;
  } else if (input == "interlock") {
    c.input = Input::kInterlock;
  } else {
    return fmt::format("unknown input \"{}\": alarm, warning, n2-flow, interlock, ain1, ain2",
                       input);
  }
  auto v = on_off(w[3]);
  if (!v) return fmt::format("\"{}\" is not on or off", w[3]);
  c.on = *v;
  return c;
}

std::string_view control_help() noexcept {
  return R"(Commands (one per line, on standard input or the --control FIFO):
  set MAC alarm on|off        pump alarm ("Pump Fail"); the pump stops
  set MAC warning on|off      pump warning
  set MAC n2-flow on|off      N2 purge flow present (on = ok)
  set MAC interlock on|off    interlock satisfied (on = ok)
  set MAC ain1|ain2 VALUE     analog input: volts ("2.5V", 0..10) or counts (0..4095)
  set MAC param N VALUE       a device driven by its EDS: its ParamN (1, 0x5A, -2.5),
                              then a change-of-state message if one is due
  fault MAC|all FAULT on|off  Identity fault on or off; FAULT: minor-recoverable (DOP
                              short), minor-unrecoverable, major-recoverable (+24 V lost;
                              State 4), major-unrecoverable (checksum, A/D; State 5).
                              A major fault applies the outputs' fault actions and holds
                              them there (polls answered, not applied) until cleared
  power-cycle MAC|all         power off and on: volatile state lost, duplicate MAC check;
                              E2 settings kept; unrecoverable faults end, recoverable stay
  power-off MAC|all           the device goes silent until power-on
  power-on MAC|all            (after power-off: a power cycle, as above)
  status [MAC]                network state, owner, outputs, inputs, Identity state and
                              faults of each device
  help
  quit                        (end of input quits too, unless --control is given)
Pump running follows the Pump On output the master sets, after the pump's spin-up
time, and drops with an alarm or an open interlock.
Each command is answered with one line: "ok ..." or "error: ...".
)";
}

}  // namespace dnbridge::sim::host
