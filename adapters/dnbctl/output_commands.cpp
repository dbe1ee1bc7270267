// pump, ballast, aout: command one output of a pump, keep the others as the
// device applies them, and wait for the bridge's echo.
#include <fmt/format.h>

#include <chrono>
#include <cstdio>

#include "adapters/dds/fields.hpp"
#include "adapters/dnbctl/commander.hpp"
#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/target.hpp"
#include "adapters/dnbctl/values.hpp"

namespace dnbridge::dnbctl {
namespace {

// While waiting for the echo, and while holding, the command is written
// again this often: a bridge whose command reader matched late still gets
// it, and --hold-for keeps it current.
constexpr auto kRewritePeriod = std::chrono::seconds(1);

constexpr const char* kLifetimeNote =
    "A command stays in force only while a commander is live: when dnbctl exits its command "
    "writer goes away and the bridge puts the pump's outputs idle (the device's own idle state), "
    "unless the node's no-commander policy is \"hold\", or passes the pump to the next strongest "
    "live commander. --hold-for SECONDS keeps commanding (written again every second) until the "
    "time is up or Ctrl-C. The outputs not named keep the values the device applies now (all off "
    "and 0 when the outputs are idle).";

std::string_view output_name(Output o) {
  switch (o) {
    case Output::kPump: return "pump";
    case Output::kBallast: return "ballast";
    case Output::kAnalog: return "aout";
  }
  return "";
}

Outputs applied_outputs(const dnbridge_PumpState& s) {
  if (s.outputs_idle) return Outputs{};  // idle: the device's idle state, not ours to keep
  return Outputs{static_cast<bool>(s.pump_on), static_cast<bool>(s.n2_ballast_on), s.analog_output_raw};
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

}  // namespace

CLI::App* add_output(CLI::App& app, Output output, OutputArgs& args) {
  CLI::App* cmd = nullptr;
  switch (output) {
    case Output::kPump:
      cmd = app.add_subcommand("pump", "Switch a pump on or off (PumpCommand), keeping the N2 "
                                       "ballast and analog output as they are.");
      cmd->add_option("NODE", args.node, "The node: its MAC ID (0..63) or its name")->required();
      cmd->add_option("STATE", args.value, "on or off")->required();
      break;
    case Output::kBallast:
      cmd = app.add_subcommand("ballast", "Switch a pump's N2 ballast on or off (PumpCommand), "
                                          "keeping the pump and analog output as they are.");
      cmd->add_option("NODE", args.node, "The node: its MAC ID (0..63) or its name")->required();
      cmd->add_option("STATE", args.value, "on or off")->required();
      break;
    case Output::kAnalog:
      cmd = app.add_subcommand("aout", "Set a pump interface's analog output (PumpCommand), "
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
  const NodeKey key = find_node(client, o, *ref);
  const std::string name = node_name(key.rack, key.port, key.mac);
  // The outputs the device applies now (transient-local: at once).
  if (!client.wait_until(deadline_after(o.timeout()), [&] { return client.pump(key) != nullptr; })) {
    throw CommandError(Exit::kNotFound,
                       fmt::format("{}: no PumpState within {:g} s", name, o.timeout_seconds));
  }
  Outputs wanted = applied_outputs(*client.pump(key)->data);
  switch (args.output) {
    case Output::kPump: wanted.pump_on = *on; break;
    case Output::kBallast: wanted.n2_ballast_on = *on; break;
    case Output::kAnalog: wanted.analog_output_raw = analog->raw; break;
  }
  const auto* status = client.node(key);
  const std::uint64_t refused_before = status ? status->data->counters.commands_refused : 0;

  Commander commander(client, args.strength, key.rack);
  const Deadline deadline = deadline_after(o.timeout());
  if (!commander.wait_matched(client, deadline)) {
    throw CommandError(
        Exit::kNotFound,
        fmt::format("{}: no bridge took commands in rack {}'s partition (dnbridge/{}) "
                    "within {:g} s: a bridge of a version before partitions reads "
                    "commands elsewhere",
                    name, key.rack, key.rack, o.timeout_seconds));
  }

  // Written, then again every kRewritePeriod, until the echo shows it applied
  // or the bridge refused it.
  const std::uint64_t samples_before = client.pump(key)->samples;
  auto next_write = std::chrono::steady_clock::now();
  const auto write_when_due = [&] {
    const auto now = std::chrono::steady_clock::now();
    if (now < next_write) return;
    if (auto s = commander.write(key, wanted, issuer); !s) {
      throw CommandError(Exit::kFailed, fmt::format("{}: writing the command failed: {}", name,
                                                    s.error().message()));
    }
    next_write = now + kRewritePeriod;
  };
  const auto refused = [&] {
    const auto* n = client.node(key);
    return n && n->data->counters.commands_refused > refused_before;
  };
  const auto applied = [&] {
    const auto& p = *client.pump(key);
    const auto& s = *p.data;
    return p.samples > samples_before && p.alive && s.online && !s.outputs_idle &&
           applied_outputs(s) == wanted && dds::view(s.commanded_by) == issuer;
  };
  const bool ended = client.wait_until(deadline, [&] {
    if (refused() || applied()) return true;
    write_when_due();
    return false;
  });

  const auto& state = *client.pump(key)->data;
  const auto* node = client.node(key);
  std::string failure;
  if (refused()) {
    failure = fmt::format("refused by the bridge: {}", dds::view(node->data->last_command_refused));
  } else if (!ended || !applied()) {
    if (interrupted()) {
      failure = "interrupted before the bridge showed the outputs applied";
    } else if (!client.pump(key)->alive) {
      failure = "the bridge is gone";
    } else if (!state.online) {
      failure = node ? fmt::format("the node is not online ({}: {})", to_text(node->data->state),
                                   dds::view(node->data->reason))
                     : std::string("the node is not online");
    } else if (!state.outputs_idle && dds::view(state.commanded_by) != issuer &&
               !dds::view(state.commanded_by).empty()) {
      failure = fmt::format("\"{}\" commands this pump: a live commander stronger than {} "
                            "(ownership strength) takes precedence",
                            dds::view(state.commanded_by), args.strength);
    } else {
      failure = fmt::format("the bridge did not show the outputs applied within {:g} s",
                            o.timeout_seconds);
    }
  }

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
  if (!failure.empty()) {
    std::fputs(fmt::format("dnbctl: {}: not applied: {}\n", name, failure).c_str(), stderr);
    return Exit::kFailed;
  }

  if (args.hold_for_seconds > 0) {
    if (!o.json) {
      print(fmt::format("holding for {:g} s (Ctrl-C to stop)\n", args.hold_for_seconds));
    }
    const Deadline hold_end =
        std::chrono::steady_clock::now() +
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(args.hold_for_seconds));
    client.wait_until(hold_end, [&] {
      write_when_due();
      return false;
    });
  } else if (!o.json) {
    std::fputs("dnbctl: note: the command ends when dnbctl exits, unless the bridge's policy for "
               "the node is \"hold\" (see --hold-for)\n",
               stderr);
  }
  return Exit::kOk;
}

}  // namespace dnbridge::dnbctl
