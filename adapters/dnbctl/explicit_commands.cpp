// get, set, service: explicit messaging with a node through its bridge
// (ExplicitRequest / ExplicitReply).
#include <fmt/format.h>

#include <cstdio>

#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/requester.hpp"
#include "adapters/dnbctl/target.hpp"
#include "adapters/dnbctl/values.hpp"
#include "bridge/cip/service.hpp"

namespace dnbridge::dnbctl {
namespace {

constexpr const char* kStatusNote =
    "Numbers are decimal or hex with 0x. The bridge's transaction status is printed with its "
    "name (1 transaction completed, 2 in progress, 3 slave not in scan list, 4 slave off-line, "
    "5 port off-line, 6 TXID unknown, 8 invalid command, 9 out of buffers, 10 other transaction "
    "in progress, 11 could not connect, 12 response too large, 13 invalid port, 14 invalid size, "
    "15 connection busy), then the device's CIP general status with its name. Exit 0 only when "
    "both say success.";

template <class T>
T number(const std::string& text, std::uint64_t max, std::string_view what) {
  auto v = parse_unsigned(text, max, what);
  if (!v) throw CommandError(Exit::kUsage, v.error());
  return static_cast<T>(*v);
}

std::vector<std::uint8_t> bytes(const std::string& text) {
  auto v = parse_hex_bytes(text);
  if (!v) throw CommandError(Exit::kUsage, v.error());
  return *v;
}

}  // namespace

CLI::App* add_explicit(CLI::App& app, ExplicitKind kind, ExplicitArgs& args) {
  CLI::App* cmd = nullptr;
  switch (kind) {
    case ExplicitKind::kGet:
      cmd = app.add_subcommand("get",
                               "Read an attribute (Get_Attribute_Single, 0x0E) of a node "
                               "through its bridge; the data in hex, and decoded with --as.");
      break;
    case ExplicitKind::kSet:
      cmd = app.add_subcommand("set",
                               "Write an attribute (Set_Attribute_Single, 0x10) of a node "
                               "through its bridge.");
      break;
    case ExplicitKind::kService:
      cmd = app.add_subcommand("service",
                               "Send any CIP service to a node through its bridge "
                               "(e.g. Reset, 0x05, to class 1 instance 1).");
      break;
  }
  cmd->add_option("NODE", args.node, "The node: its MAC ID (0..63) or its name")->required();
  if (kind == ExplicitKind::kService) {
    cmd->add_option("SERVICE", args.service, "CIP service code (0..0x7F)")->required();
  }
  cmd->add_option("CLASS", args.class_id, "Class ID (0..0xFFFF)")->required();
  cmd->add_option("INSTANCE", args.instance_id, "Instance ID (0..0xFFFF)")->required();
  if (kind != ExplicitKind::kService) {
    cmd->add_option("ATTRIBUTE", args.attribute, "Attribute ID (0..255)")->required();
  }
  if (kind == ExplicitKind::kSet) {
    cmd->add_option("HEXBYTES", args.data, "The attribute's value, hex bytes (e.g. 01, \"00 08\")")
        ->required();
  }
  if (kind == ExplicitKind::kService) {
    cmd->add_option("HEXDATA", args.data, "Service data, hex bytes (default none)");
  }
  if (kind != ExplicitKind::kSet) {
    cmd->add_option("--as", args.as,
                    "Also decode the reply data: string (SHORT_STRING), uint or int "
                    "(little-endian, 1, 2, 4 or 8 bytes)")
        ->check(CLI::IsMember({"string", "uint", "int"}));
  }
  cmd->footer(kStatusNote);
  args.kind = kind;
  return cmd;
}

Exit run_explicit(const GlobalOptions& o, const ExplicitArgs& args) {
  auto ref = parse_node(args.node);
  if (!ref) throw CommandError(Exit::kUsage, ref.error());
  ExplicitExchange x;
  switch (args.kind) {
    case ExplicitKind::kGet:
      x.service = cip::code(cip::Service::kGetAttributeSingle);
      break;
    case ExplicitKind::kSet:
      x.service = cip::code(cip::Service::kSetAttributeSingle);
      break;
    case ExplicitKind::kService:
      // Bit 7 of the service byte is the response flag.
      x.service = number<std::uint8_t>(args.service, 0x7F, "service");
      break;
  }
  x.class_id = number<std::uint16_t>(args.class_id, 0xFFFF, "class");
  x.instance_id = number<std::uint16_t>(args.instance_id, 0xFFFF, "instance");
  if (args.kind != ExplicitKind::kService) {
    x.attribute = number<std::uint8_t>(args.attribute, 0xFF, "attribute");
  }
  if (args.kind == ExplicitKind::kSet && args.data.empty()) {
    throw CommandError(Exit::kUsage, "set needs the attribute's value as hex bytes");
  }
  x.request_data = bytes(args.data);
  Decoding as = Decoding::kNone;
  if (!args.as.empty()) {
    auto d = parse_decoding(args.as);
    if (!d) throw CommandError(Exit::kUsage, d.error());
    as = *d;
  }
  install_interrupt_handlers();

  Client client = make_client(o);
  const NodeKey target = find_port(client, o, *ref);
  x.rack = target.rack;
  x.port = target.port;
  x.mac = target.mac;
  Requester requester(client, requester_name(), x.rack);
  if (!requester.execute(client, x, deadline_after(o.timeout()))) {
    throw CommandError(Exit::kNotFound,
                       fmt::format("{}: no reply from the bridge of rack \"{}\" within {:g} s",
                                   node_name(x.rack, x.port, x.mac), x.rack, o.timeout_seconds));
  }

  std::optional<Parsed<std::string>> decoded;
  if (as != Decoding::kNone && x.succeeded()) decoded = decode_data(x.data, as);
  if (o.json) {
    JsonWriter out;
    explicit_json(out, x, as, decoded);
    print(out.str() + "\n");
  } else {
    print(explicit_text(x, as, decoded));
  }
  if (!x.succeeded()) {
    // The bridge's own refusal says why (e.g. which [explicit_policy] key
    // would allow the request): on stderr too, for whoever reads only that.
    std::fputs(fmt::format("dnbctl: {}: {} failed: {}\n", node_name(x.rack, x.port, x.mac),
                           service_text(x.service), failure_text(x))
                   .c_str(),
               stderr);
    return Exit::kFailed;
  }
  if (decoded && !decoded->ok()) {
    std::fputs(fmt::format("dnbctl: cannot decode the data: {}\n", decoded->error()).c_str(),
               stderr);
    return Exit::kFailed;
  }
  return Exit::kOk;
}

}  // namespace dnbridge::dnbctl
