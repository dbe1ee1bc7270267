// pump, ballast, aout: command one output of a pump, keep the others as the
// device applies them, and wait for the bridge's echo. outputs: command a
// device's outputs (profile "eds"), by field or as bytes, and wait for the
// echo in DeviceState.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <span>

#include "adapters/dds/fields.hpp"
#include "adapters/dnbctl/commander.hpp"
#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/target.hpp"
#include "adapters/dnbctl/values.hpp"
#include "bridge/common/text.hpp"
#include "bridge/profiles/eds/eds_file.hpp"

namespace dnbridge::dnbctl {
namespace {

constexpr const char* kLifetimeNote =
    "A command stays in force only while a commander is live: when dnbctl exits its command "
    "writer goes away and the bridge puts the pump's outputs idle (the device's own idle state), "
    "unless the node's no-commander policy is \"hold\", or passes the pump to the next strongest "
    "live commander. --hold-for SECONDS keeps commanding (written again every second, or four "
    "times per command refresh when the node has one: NodeStatus command_refresh_ms) until the "
    "time is up or Ctrl-C. The outputs not named keep the values the device applies now (all off "
    "and 0 when the outputs are idle).";

std::string_view output_name(Output o) {
  switch (o) {
    case Output::kPump:
      return "pump";
    case Output::kBallast:
      return "ballast";
    case Output::kAnalog:
      return "aout";
  }
  return "";
}

Outputs applied_outputs(const dnbridge_PumpState& s) {
  if (s.outputs_idle) return Outputs{};  // idle: the device's idle state, not ours to keep
  return Outputs{static_cast<bool>(s.pump_on), static_cast<bool>(s.n2_ballast_on),
                 s.analog_output_raw};
}

std::string default_issuer() { return "dnbctl " + user_at_host(); }

void key_json(JsonWriter& out, const NodeKey& key) {
  out.field("rack", key.rack).field("port", key.port).field("mac", unsigned{key.mac});
}

void outputs_json(JsonWriter& out, const Outputs& o) {
  out.begin_object()
      .field("pump_on", o.pump_on)
      .field("n2_ballast_on", o.n2_ballast_on)
      .field("analog_output_raw", unsigned{o.analog_output_raw})
      .end_object();
}

// Writes a command at once, then again every `period` (rewrite_period,
// commander.hpp), while waiting for the echo and while holding: a bridge
// whose command reader matched late still gets it, and --hold-for keeps it
// current.
class Rewriter {
 public:
  Rewriter(std::string name, Duration period, std::function<Status()> write)
      : name_(std::move(name)),
        period_(std::chrono::duration_cast<std::chrono::steady_clock::duration>(period)),
        write_(std::move(write)) {}
  std::chrono::steady_clock::time_point next_due() const { return next_; }
  void when_due() {
    const auto now = std::chrono::steady_clock::now();
    if (now < next_) return;
    if (auto s = write_(); !s) {
      throw CommandError(Exit::kFailed, fmt::format("{}: writing the command failed: {}", name_,
                                                    s.error().message()));
    }
    next_ = now + period_;
  }

 private:
  std::string name_;
  std::chrono::steady_clock::duration period_;
  std::function<Status()> write_;
  std::chrono::steady_clock::time_point next_ = std::chrono::steady_clock::now();
};

// Writes until the bridge's echo shows the command `applied` or NodeStatus
// counts it refused, or the deadline. Empty when applied; else why not:
// the refusal, an interrupt, or `not_applied()` (what the state shows).
std::string command_until_applied(Client& client, const NodeKey& key, Deadline deadline,
                                  Rewriter& rewriter, const std::function<bool()>& applied,
                                  const std::function<std::string()>& not_applied) {
  const auto* status = client.node(key);
  const std::uint64_t refused_before = status ? status->data->counters.commands_refused : 0;
  const auto refused = [&] {
    const auto* n = client.node(key);
    return n && n->data->counters.commands_refused > refused_before;
  };
  const bool ended = client.wait_until(deadline, [&] {
    if (refused() || applied()) return true;
    rewriter.when_due();
    return false;
  });
  if (refused()) {
    return fmt::format("refused by the bridge: {}",
                       dds::view(client.node(key)->data->last_command_refused));
  }
  if (ended && applied()) return {};
  if (interrupted()) return "interrupted before the bridge showed the outputs applied";
  return not_applied();
}

// Why a node is not online, from its NodeStatus.
std::string not_online(const Client& client, const NodeKey& key) {
  const auto* node = client.node(key);
  return node ? fmt::format("the node is not online ({}: {})", to_text(node->data->state),
                            dds::view(node->data->reason))
              : std::string("the node is not online");
}

// Whether the node's state sample (PumpState or DeviceState) is a new one
// that shows this issuer's command in force: its outputs are then compared.
template <class State>
bool echoes_command(const Known<State>& k, std::uint64_t samples_before, std::string_view issuer) {
  const State& s = *k.data;
  return k.samples > samples_before && k.alive && s.online && !s.outputs_idle &&
         dds::view(s.commanded_by) == issuer;
}

// Why the echo did not come, from the node's state sample: the bridge gone,
// the node not online, a stronger commander (`what`: "pump", "device"), or
// nothing shown in time.
template <class State>
std::string not_echoed(const Client& client, const NodeKey& key, const Known<State>& k,
                       std::string_view issuer, std::int32_t strength, std::string_view what,
                       double timeout_seconds) {
  const State& state = *k.data;
  if (!k.alive) return "the bridge is gone";
  if (!state.online) return not_online(client, key);
  if (!state.outputs_idle && dds::view(state.commanded_by) != issuer &&
      !dds::view(state.commanded_by).empty()) {
    return fmt::format(
        "\"{}\" commands this {}: a live commander stronger than {} (ownership strength) takes "
        "precedence",
        dds::view(state.commanded_by), what, strength);
  }
  return fmt::format("the bridge did not show the outputs applied within {:g} s", timeout_seconds);
}

// After a command applied: --hold-for keeps writing it; else a note that it
// ends with dnbctl.
void hold_or_note(Client& client, const GlobalOptions& o, double hold_for_seconds,
                  Rewriter& rewriter) {
  if (hold_for_seconds > 0) {
    if (!o.json) print(fmt::format("holding for {:g} s (Ctrl-C to stop)\n", hold_for_seconds));
    const Deadline hold_end = std::chrono::steady_clock::now() +
                              std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  std::chrono::duration<double>(hold_for_seconds));
    for (;;) {
      rewriter.when_due();
      if (std::chrono::steady_clock::now() >= hold_end || interrupted()) break;
      (void)client.wait_until(std::min(hold_end, rewriter.next_due()), [] { return false; });
    }
  } else if (!o.json) {
    std::fputs(
        "dnbctl: note: the command ends when dnbctl exits, unless the bridge's policy for "
        "the node is \"hold\" (see --hold-for)\n",
        stderr);
  }
}

// What the node's bridge asks of its commanders, as it publishes it
// (NodeStatus.command_refresh_ms, PortStatus.max_commander_lease_ms; both
// transient-local: at once): what is not here by `deadline` is taken as
// asking nothing more than dnbctl offers anyway.
CommandTerms command_terms_of(Client& client, const NodeKey& key, Deadline deadline) {
  const auto port = [&]() -> const dnbridge_PortStatus* {
    auto it = client.ports().find(PortKey{key.rack, key.port});
    return it == client.ports().end() ? nullptr : &*it->second.data;
  };
  client.wait_until(deadline, [&] { return client.node(key) != nullptr && port() != nullptr; });
  CommandTerms terms;
  if (const auto* n = client.node(key)) terms.refresh = milliseconds(n->data->command_refresh_ms);
  if (const auto* p = port(); p && p->max_commander_lease_ms > 0) {
    terms.lease = std::min<Duration>(terms.lease, milliseconds(p->max_commander_lease_ms));
  }
  return terms;
}

// Which kind of node a command is for: each has its own state and command
// topics, and its own dnbctl commands.
enum class NodeKind { kPump, kDevice };

// The node named, once its state sample (PumpState or DeviceState,
// transient-local: at once) is here. A node of the other kind is refused:
// its own commands serve it.
NodeKey node_of_kind(Client& client, const GlobalOptions& o, const NodeRef& ref, NodeKind kind) {
  const NodeKey key = find_node(client, o, ref);
  const std::string name = node_name(key.rack, key.port, key.mac);
  const bool pump = kind == NodeKind::kPump;
  if (!client.wait_until(deadline_after(o.timeout()), [&] {
        return client.pump(key) != nullptr || client.device(key) != nullptr;
      })) {
    throw CommandError(Exit::kNotFound,
                       fmt::format("{}: no {} within {:g} s", name,
                                   pump ? "PumpState" : "DeviceState", o.timeout_seconds));
  }
  if (pump && client.pump(key) == nullptr) {
    throw CommandError(Exit::kUsage, fmt::format("{} is a device of profile \"eds\", not a "
                                                 "pump: outputs commands it",
                                                 name));
  }
  if (!pump && client.device(key) == nullptr) {
    throw CommandError(Exit::kUsage, fmt::format("{} is a pump (a CDN127): pump, ballast and "
                                                 "aout command it",
                                                 name));
  }
  return key;
}

// Waits until a bridge of the node's rack takes the writer's commands.
template <class Writer>
void wait_for_bridge(Client& client, Writer& writer, const NodeKey& key, Deadline deadline,
                     std::string_view what, double timeout_seconds) {
  if (writer.wait_matched(client, deadline)) return;
  throw CommandError(Exit::kNotFound,
                     fmt::format("{}: no bridge took {} in rack {}'s partition (dnbridge/{}) "
                                 "within {:g} s",
                                 node_name(key.rack, key.port, key.mac), what, key.rack, key.rack,
                                 timeout_seconds));
}

// The end of an output command: the failure reported, or --hold-for.
Exit report_or_hold(Client& client, const GlobalOptions& o, const std::string& name,
                    const std::string& failure, double hold_for_seconds, Rewriter& rewriter) {
  if (!failure.empty()) {
    std::fputs(fmt::format("dnbctl: {}: not applied: {}\n", name, failure).c_str(), stderr);
    return Exit::kFailed;
  }
  hold_or_note(client, o, hold_for_seconds, rewriter);
  return Exit::kOk;
}

}  // namespace

CLI::App* add_output(CLI::App& app, Output output, OutputArgs& args) {
  CLI::App* cmd = nullptr;
  switch (output) {
    case Output::kPump:
      cmd = app.add_subcommand("pump",
                               "Switch a pump on or off (PumpCommand), keeping the N2 "
                               "ballast and analog output as they are.");
      cmd->add_option("NODE", args.node, "The node: its MAC ID (0..63) or its name")->required();
      cmd->add_option("STATE", args.value, "on or off")->required();
      break;
    case Output::kBallast:
      cmd = app.add_subcommand("ballast",
                               "Switch a pump's N2 ballast on or off (PumpCommand), "
                               "keeping the pump and analog output as they are.");
      cmd->add_option("NODE", args.node, "The node: its MAC ID (0..63) or its name")->required();
      cmd->add_option("STATE", args.value, "on or off")->required();
      break;
    case Output::kAnalog:
      cmd = app.add_subcommand("aout",
                               "Set a pump interface's analog output (PumpCommand), "
                               "keeping the pump and N2 ballast as they are.");
      cmd->add_option("NODE", args.node, "The node: its MAC ID (0..63) or its name")->required();
      cmd->add_option("VALUE", args.value,
                      "Volts with a V suffix, 0..10 (5.0V: rounded to the nearest of 4096 steps, "
                      "round(V*4095/10)), or a raw count 0..4095 (2048, 0x800)")
          ->required();
      break;
  }
  cmd->footer(kLifetimeNote);
  cmd->add_option("--issuer", args.issuer,
                  "Who commands, as the bridge shows it (default \"dnbctl USER@HOST\")");
  cmd->add_option("--strength", args.strength,
                  "Ownership strength: the strongest live commander of a pump commands it")
      ->capture_default_str();
  cmd->add_option("--hold-for", args.hold_for_seconds,
                  "Keep commanding for SECONDS once applied (until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  args.output = output;
  return cmd;
}

Exit run_output(const GlobalOptions& o, const OutputArgs& args) {
  // Everything typed is checked before anything is sent.
  auto ref = parse_node(args.node);
  if (!ref) throw CommandError(Exit::kUsage, ref.error());
  std::optional<bool> on;
  std::optional<AnalogValue> analog;
  if (args.output == Output::kAnalog) {
    auto v = parse_analog(args.value);
    if (!v) throw CommandError(Exit::kUsage, v.error());
    analog = *v;
  } else {
    auto v = parse_on_off(args.value);
    if (!v) throw CommandError(Exit::kUsage, v.error());
    on = *v;
  }
  const std::string issuer = args.issuer.empty() ? default_issuer() : args.issuer;
  install_interrupt_handlers();

  Client client = make_client(o);
  const NodeKey key = node_of_kind(client, o, *ref, NodeKind::kPump);
  const std::string name = node_name(key.rack, key.port, key.mac);
  Outputs wanted = applied_outputs(*client.pump(key)->data);
  switch (args.output) {
    case Output::kPump:
      wanted.pump_on = *on;
      break;
    case Output::kBallast:
      wanted.n2_ballast_on = *on;
      break;
    case Output::kAnalog:
      wanted.analog_output_raw = analog->raw;
      break;
  }
  const CommandTerms terms = command_terms_of(client, key, deadline_after(o.timeout()));
  Commander<dnbridge_PumpCommand> commander(client, args.strength, key.rack, terms);
  const Deadline deadline = deadline_after(o.timeout());
  wait_for_bridge(client, commander, key, deadline,
                  "commands (a bridge of a version before partitions reads them elsewhere)",
                  o.timeout_seconds);

  // Written, then again every rewrite period, until the echo shows it applied
  // or the bridge refused it.
  const std::uint64_t samples_before = client.pump(key)->samples;
  Rewriter rewriter(name, rewrite_period(terms.refresh),
                    [&] { return commander.write(key, wanted, issuer); });
  const std::string failure = command_until_applied(
      client, key, deadline, rewriter,
      [&] {
        const auto& p = *client.pump(key);
        return echoes_command(p, samples_before, issuer) && applied_outputs(*p.data) == wanted;
      },
      [&] {
        return not_echoed(client, key, *client.pump(key), issuer, args.strength, "pump",
                          o.timeout_seconds);
      });
  const auto& state = *client.pump(key)->data;
  const auto* node = client.node(key);

  if (o.json) {
    JsonWriter out;
    out.begin_object();
    key_json(out, key);
    out.field("command", output_name(args.output)).field("issuer", issuer);
    out.key("requested");
    outputs_json(out, wanted);
    out.field("applied", failure.empty()).field("reason", failure);
    if (node) out.field("last_command_refused", dds::view(node->data->last_command_refused));
    out.key("state");
    pump_json(out, state);
    out.end_object();
    print(out.str() + "\n");
  } else if (failure.empty()) {
    print(fmt::format("{} ({}): applied: {}; commanded by \"{}\"\n", name, dds::view(state.name),
                      outputs_text(wanted.pump_on, wanted.n2_ballast_on, wanted.analog_output_raw),
                      issuer));
  }
  return report_or_hold(client, o, name, failure, args.hold_for_seconds, rewriter);
}

}  // namespace dnbridge::dnbctl

namespace dnbridge::dnbctl {
namespace {

constexpr const char* kDeviceLifetimeNote =
    "A device's outputs are given whole: every numeric field of its output data (dnbctl show "
    "NODE lists them), or the data's bytes with --bytes. The bridge checks the command against "
    "the device's EDS (types, limits, padding) and refuses it whole, with the reason, if any "
    "part is wrong. A command stays in force only while a commander is live: when dnbctl exits "
    "the device goes to its configured idle state, unless the node's no-commander policy is "
    "\"hold\"; --hold-for SECONDS keeps commanding until the time is up or Ctrl-C.";

// NAME=VALUE: the value a number (1, -2.5, 0x81).
Parsed<std::pair<std::string, double>> parse_field(std::string_view text) {
  const auto eq = text.rfind('=');
  if (eq == std::string_view::npos || eq == 0) {
    return Parsed<std::pair<std::string, double>>::failure(
        fmt::format("\"{}\" is not NAME=VALUE (e.g. \"Digital outputs=0x81\")", text));
  }
  const std::string value(text.substr(eq + 1));
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (value.empty() || end != value.c_str() + value.size() || !std::isfinite(v)) {
    return Parsed<std::pair<std::string, double>>::failure(
        fmt::format("\"{}\": {} is not a number", text, value));
  }
  return std::pair{std::string(text.substr(0, eq)), v};
}

// Whether DeviceState shows `wanted` applied: its bytes, or each field
// given, found by its name or its ParamN, with the value given (a REAL's as
// the device holds it: single precision). A field given that DeviceState
// does not have is not shown.
bool shows(const dnbridge_DeviceState& s, const DeviceOutputs& wanted) {
  const auto out = dds::view(s.outputs);
  if (!wanted.bytes.empty()) {
    return std::equal(out.begin(), out.end(), wanted.bytes.begin(), wanted.bytes.end());
  }
  const std::span<const dnbridge_DeviceField> fields(s.output_fields._buffer,
                                                     s.output_fields._length);
  for (const auto& [name, value] : wanted.fields) {
    const auto number = profiles::eds::param_number(name);
    const auto it = std::find_if(fields.begin(), fields.end(), [&](const dnbridge_DeviceField& f) {
      return number ? f.param == *number : iequals(dds::view(f.name), name);
    });
    if (it == fields.end()) return false;
    const double expected =
        dds::view(it->type) == "REAL" ? static_cast<double>(static_cast<float>(value)) : value;
    if (it->value != expected) return false;
  }
  return true;
}

}  // namespace

CLI::App* add_device_outputs(CLI::App& app, DeviceOutputArgs& args) {
  auto* cmd = app.add_subcommand(
      "outputs",
      "Command a device's outputs (DeviceCommand): a node of profile \"eds\", by "
      "its EDS fields (NAME=VALUE ...) or as bytes (--bytes).");
  cmd->add_option("NODE", args.node, "The node: its MAC ID (0..63) or its name")->required();
  cmd->add_option("FIELDS", args.fields,
                  "Every numeric field of the outputs as NAME=VALUE (the EDS parameter's name, "
                  "or ParamN where names repeat; the value as the device holds it, not scaled)");
  cmd->add_option("--bytes", args.bytes, "The output data's bytes in hex (\"81 00\", 8100)");
  cmd->footer(kDeviceLifetimeNote);
  cmd->add_option("--issuer", args.issuer,
                  "Who commands, as the bridge shows it (default \"dnbctl USER@HOST\")");
  cmd->add_option("--strength", args.strength,
                  "Ownership strength: the strongest live commander of a device commands it")
      ->capture_default_str();
  cmd->add_option("--hold-for", args.hold_for_seconds,
                  "Keep commanding for SECONDS once applied (until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  return cmd;
}

Exit run_device_outputs(const GlobalOptions& o, const DeviceOutputArgs& args) {
  // Everything typed is checked before anything is sent.
  auto ref = parse_node(args.node);
  if (!ref) throw CommandError(Exit::kUsage, ref.error());
  DeviceOutputs wanted;
  if (!args.bytes.empty() && !args.fields.empty()) {
    throw CommandError(Exit::kUsage, "give the outputs as FIELDS or as --bytes, not both");
  }
  if (!args.bytes.empty()) {
    auto b = parse_hex_bytes(args.bytes);
    if (!b) throw CommandError(Exit::kUsage, b.error());
    if (b->empty()) throw CommandError(Exit::kUsage, "--bytes: no byte given");
    wanted.bytes = *b;
  } else if (args.fields.empty()) {
    throw CommandError(Exit::kUsage, "give the outputs: FIELDS (NAME=VALUE ...) or --bytes");
  }
  for (const auto& text : args.fields) {
    auto f = parse_field(text);
    if (!f) throw CommandError(Exit::kUsage, f.error());
    wanted.fields.push_back(*f);
  }
  const std::string issuer = args.issuer.empty() ? default_issuer() : args.issuer;
  install_interrupt_handlers();

  Client client = make_client(o);
  const NodeKey key = node_of_kind(client, o, *ref, NodeKind::kDevice);
  const std::string name = node_name(key.rack, key.port, key.mac);
  const CommandTerms terms = command_terms_of(client, key, deadline_after(o.timeout()));
  Commander<dnbridge_DeviceCommand> commander(client, args.strength, key.rack, terms);
  const Deadline deadline = deadline_after(o.timeout());
  wait_for_bridge(client, commander, key, deadline, "device commands", o.timeout_seconds);
  const std::uint64_t samples_before = client.device(key)->samples;
  Rewriter rewriter(name, rewrite_period(terms.refresh),
                    [&] { return commander.write(key, wanted, issuer); });
  const std::string failure = command_until_applied(
      client, key, deadline, rewriter,
      [&] {
        const auto& d = *client.device(key);
        return echoes_command(d, samples_before, issuer) && shows(*d.data, wanted);
      },
      [&] {
        return not_echoed(client, key, *client.device(key), issuer, args.strength, "device",
                          o.timeout_seconds);
      });
  const auto& state = *client.device(key)->data;
  const auto applied_bytes = hex_bytes(std::span<const std::uint8_t>(dds::view(state.outputs)));
  if (o.json) {
    JsonWriter out;
    out.begin_object();
    key_json(out, key);
    out.field("command", "outputs").field("issuer", issuer);
    out.field("applied", failure.empty()).field("reason", failure);
    out.field("outputs", applied_bytes);
    if (const auto* node = client.node(key)) {
      out.field("last_command_refused", dds::view(node->data->last_command_refused));
    }
    out.end_object();
    print(out.str() + "\n");
  } else if (failure.empty()) {
    print(fmt::format("{} ({}): applied: [{}]; commanded by \"{}\"\n", name, dds::view(state.name),
                      applied_bytes, issuer));
  }
  return report_or_hold(client, o, name, failure, args.hold_for_seconds, rewriter);
}

}  // namespace dnbridge::dnbctl
