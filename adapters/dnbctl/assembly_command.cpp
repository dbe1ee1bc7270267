// assembly: what a node's Assembly object (class 0x04) says of itself, read
// through its bridge (shared/seeds/003): the class's revision and max
// instance, and each instance's member list (sizes in bits, paths decoded to
// class/instance/attribute, padding shown as padding).
#include <fmt/format.h>

#include <cstdio>

#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/requester.hpp"
#include "adapters/dnbctl/target.hpp"
#include "adapters/dnbctl/values.hpp"
#include "bridge/cip/assembly.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/common/bytes.hpp"

namespace dnbridge::dnbctl {
namespace {

constexpr std::uint16_t kAssemblyClass = 0x04;
// CIP general status "object does not exist": an instance the device has not.
constexpr std::uint8_t kObjectDoesNotExist = 0x16;
// Instances asked for when none is named: at most up to this.
constexpr std::uint16_t kMaxInstancesScanned = 255;

// Reads one attribute, waiting `timeout` for its reply; the exchange (its
// reply's status says how it went).
ExplicitExchange get(Client& client, Requester& requester, const NodeKey& node,
                     std::uint16_t instance, std::uint8_t attribute, Duration timeout) {
  ExplicitExchange x;
  x.rack = node.rack;
  x.port = node.port;
  x.mac = node.mac;
  x.service = cip::code(cip::Service::kGetAttributeSingle);
  x.class_id = kAssemblyClass;
  x.instance_id = instance;
  x.attribute = attribute;
  if (!requester.execute(client, x, deadline_after(timeout))) {
    if (interrupted()) throw CommandError(Exit::kFailed, "interrupted");
    throw CommandError(Exit::kNotFound,
                       fmt::format("{}: no reply from the bridge of rack \"{}\" to the Get of "
                                   "instance {} attribute {}",
                                   node_name(x.rack, x.port, x.mac), x.rack, instance, attribute));
  }
  return x;
}

// "the device answered 0x14 (attribute not supported)", the bridge's status,
// or a reply of another size than a UINT's.
std::string uint_failure_text(const ExplicitExchange& x) {
  if (x.succeeded()) return fmt::format("{} byte(s), a UINT expected", x.data.size());
  return failure_text(x);
}

std::optional<std::uint16_t> uint16_of(const ExplicitExchange& x) {
  if (!x.succeeded() || x.data.size() != 2) return std::nullopt;
  return static_cast<std::uint16_t>(x.data[0] | (x.data[1] << 8));
}

struct InstanceReport {
  std::uint16_t instance = 0;
  std::optional<std::uint16_t> members;   // attribute 1
  std::vector<cip::AssemblyMember> list;  // attribute 2, decoded
  std::string list_problem;               // why there is no list
};

// One instance's attributes 1 and 2; nothing when the device has no such
// instance.
std::optional<InstanceReport> read_instance(Client& client, Requester& requester,
                                            const NodeKey& node, std::uint16_t instance,
                                            Duration timeout) {
  InstanceReport r;
  r.instance = instance;
  const ExplicitExchange count = get(client, requester, node, instance, 1, timeout);
  if (count.status == 1 && count.general_status == kObjectDoesNotExist) return std::nullopt;
  r.members = uint16_of(count);
  const ExplicitExchange list = get(client, requester, node, instance, 2, timeout);
  if (list.status == 1 && list.general_status == kObjectDoesNotExist) return std::nullopt;
  if (!list.succeeded()) {
    r.list_problem = fmt::format("member list not read: {}", failure_text(list));
    return r;
  }
  auto decoded = cip::decode_member_list(Bytes(list.data.data(), list.data.size()));
  if (!decoded) {
    r.list_problem = fmt::format("member list [{}] does not decode: {}", hex_bytes(list.data),
                                 decoded.error().message());
    return r;
  }
  r.list = std::move(*decoded);
  return r;
}

std::string instance_text(const InstanceReport& r) {
  std::string s = fmt::format("instance {}:", r.instance);
  if (r.members) s += fmt::format(" {} member(s)", *r.members);
  if (!r.list_problem.empty()) return s + fmt::format(" ({})\n", r.list_problem);
  s += fmt::format(", {} bits\n", cip::member_bits(r.list));
  for (std::size_t i = 0; i < r.list.size(); ++i) {
    const auto& m = r.list[i];
    s += fmt::format("  {:>3}  {:>5} bits  {}\n", i + 1, m.bits, cip::describe_path(m));
  }
  return s;
}

void instance_json(JsonWriter& out, const InstanceReport& r) {
  out.begin_object().field("instance", unsigned{r.instance});
  if (r.members) out.field("number_of_members", unsigned{*r.members});
  out.field("problem", r.list_problem).key("members").begin_array();
  for (const auto& m : r.list) {
    out.begin_object()
        .field("bits", unsigned{m.bits})
        .field("padding", m.padding())
        .field("path", hex_bytes(m.path_bytes))
        .field("describes", cip::describe_path(m))
        .end_object();
  }
  out.end_array().end_object();
}

}  // namespace

CLI::App* add_assembly(CLI::App& app, AssemblyArgs& args) {
  auto* cmd = app.add_subcommand(
      "assembly",
      "Read a node's Assembly object (class 0x04) through its bridge: the class's revision and "
      "max instance, and the member list of INSTANCE, or of every instance up to the max (sizes "
      "in bits, paths as class/instance/attribute, padding).");
  cmd->add_option("NODE", args.node, "The node: its MAC ID (0..63) or its name")->required();
  cmd->add_option("INSTANCE", args.instance, "One assembly instance (default: every one)");
  return cmd;
}

Exit run_assembly(const GlobalOptions& o, const AssemblyArgs& args) {
  auto ref = parse_node(args.node);
  if (!ref) throw CommandError(Exit::kUsage, ref.error());
  std::optional<std::uint16_t> only;
  if (!args.instance.empty()) {
    auto v = parse_unsigned(args.instance, 0xFFFF, "instance");
    if (!v) throw CommandError(Exit::kUsage, v.error());
    if (*v == 0) throw CommandError(Exit::kUsage, "instance 0 is the class: give 1..65535");
    only = static_cast<std::uint16_t>(*v);
  }
  install_interrupt_handlers();
  Client client = make_client(o);
  const NodeKey node = find_port(client, o, *ref);
  const std::string name = node_name(node.rack, node.port, node.mac);
  Requester requester(client, requester_name(), node.rack);
  const Duration timeout = o.timeout();

  const ExplicitExchange revision = get(client, requester, node, 0, 1, timeout);
  const ExplicitExchange max = get(client, requester, node, 0, 2, timeout);
  if (revision.status != 1 && max.status != 1) {
    throw CommandError(Exit::kFailed, fmt::format("{}: {}", name, uint_failure_text(max)));
  }
  std::vector<InstanceReport> instances;
  std::vector<std::uint16_t> absent;  // named, and not there
  if (only) {
    if (auto r = read_instance(client, requester, node, *only, timeout)) {
      instances.push_back(std::move(*r));
    } else {
      absent.push_back(*only);
    }
  } else if (auto n = uint16_of(max)) {
    const std::uint16_t last = std::min(*n, kMaxInstancesScanned);
    for (std::uint16_t i = 1; i <= last && !interrupted(); ++i) {
      if (auto r = read_instance(client, requester, node, i, timeout)) {
        instances.push_back(std::move(*r));
      }
    }
  }

  const auto class_attribute = [&](const ExplicitExchange& x) {
    const auto v = uint16_of(x);
    return v ? fmt::format("{}", *v) : fmt::format("not read ({})", uint_failure_text(x));
  };
  if (o.json) {
    JsonWriter out;
    out.begin_object()
        .field("rack", node.rack)
        .field("port", node.port)
        .field("mac", unsigned{node.mac});
    if (auto v = uint16_of(revision)) out.field("revision", unsigned{*v});
    if (auto v = uint16_of(max)) out.field("max_instance", unsigned{*v});
    out.key("instances").begin_array();
    for (const auto& r : instances) instance_json(out, r);
    out.end_array().end_object();
    print(out.str() + "\n");
  } else {
    std::string text = fmt::format("{} Assembly (class 0x04): revision {}, max instance {}\n", name,
                                   class_attribute(revision), class_attribute(max));
    for (const auto& r : instances) text += instance_text(r);
    if (!only && !uint16_of(max)) {
      text += "no max instance read: name an INSTANCE to read its member list\n";
    }
    if (!only && uint16_of(max).value_or(0) > kMaxInstancesScanned) {
      text +=
          fmt::format("instances above {} not read: name one as INSTANCE\n", kMaxInstancesScanned);
    }
    print(text);
  }
  if (!absent.empty()) {
    std::fputs(fmt::format("dnbctl: {}: no assembly instance {}\n", name, absent.front()).c_str(),
               stderr);
    return Exit::kFailed;
  }
  return Exit::kOk;
}

}  // namespace dnbridge::dnbctl
