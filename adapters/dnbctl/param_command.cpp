// param: a device's parameter read, or written and read back, by its name in
// the device's EDS, through the bridge's explicit gateway (ExplicitRequest):
// the attribute its link path names, the value in its type, units and
// limits. A write is a Set_Attribute_Single the gateway guards as any other
// ([explicit_policy]: a parameter the bridge sets at start-up needs
// allow_managed_attribute_writes).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/requester.hpp"
#include "adapters/dnbctl/target.hpp"
#include "adapters/dnbctl/values.hpp"
#include "bridge/cip/assembly.hpp"
#include "bridge/cip/objects.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/profiles/eds/io_layout.hpp"
#include "bridge/profiles/eds/node_profile.hpp"

namespace dnbridge::dnbctl {
namespace {

constexpr const char* kParamNote =
    "The parameter's attribute is its EDS link path (read through the Parameter object's "
    "instance N attribute 1 where it has none; only a numeric parameter with a link path is "
    "written). A value is given as the device holds it, unscaled (the EDS's limits are in these "
    "units), and checked against the parameter's type and limits, and the node's identity "
    "against the EDS's, before it is sent; the bridge's [explicit_policy] decides whether it may "
    "be written (a parameter the bridge sets at start-up needs allow_managed_attribute_writes). "
    "After a write the value is read back: another value than the one written is an error.";

// The attribute that holds parameter `p`.
devicenet::AttributeSetting target_of(const profiles::eds::Param& p) {
  devicenet::AttributeSetting t;
  const cip::EPath& link = p.link;
  if (link.class_id && link.instance_id && link.attribute && *link.class_id <= 0xFFFF &&
      *link.instance_id <= 0xFFFF && *link.attribute <= 0xFF) {
    t.class_id = static_cast<std::uint16_t>(*link.class_id);
    t.instance_id = static_cast<std::uint16_t>(*link.instance_id);
    t.attribute = static_cast<std::uint8_t>(*link.attribute);
  } else {
    t.class_id = cip::class_id::kParameter;
    t.instance_id = static_cast<std::uint16_t>(p.number);
    t.attribute = 1;
  }
  return t;
}

// The value `data` holds as the parameter's type reads it: a number (a REAL
// as the single-precision value it is), exactly for 64-bit integers; empty
// when it is not a finite number of the parameter's size.
std::optional<std::string> raw_text(const profiles::eds::Param& p, Bytes data) {
  if (p.type.size == 0 || data.size() != p.size) return std::nullopt;
  const std::uint64_t raw = little_endian(data);
  const auto bits = static_cast<std::uint16_t>(p.size * 8);
  if (!p.type.is_float) {
    if (!p.type.is_signed) return fmt::format("{}", raw);
    if (p.size >= 8) return fmt::format("{}", static_cast<std::int64_t>(raw));
    return fmt::format("{}", static_cast<std::int64_t>(profiles::eds::from_raw(p.type, bits, raw)));
  }
  const double v = profiles::eds::from_raw(p.type, bits, raw);
  if (!std::isfinite(v)) return std::nullopt;
  return p.size == 4 ? fmt::format("{}", static_cast<float>(v)) : fmt::format("{}", v);
}

// "5 ms"; with the EDS's scaling "5.0 ms (raw 50)"; the bytes when they are
// not a number of the parameter's size.
std::string value_text(const profiles::eds::Param& p, Bytes data) {
  const auto raw = raw_text(p, data);
  if (!raw) return hex_bytes(data);
  const std::string units = p.units.empty() ? "" : " " + p.units;
  if (p.multiplier == 1 && p.divisor == 1 && p.base == 1 && p.offset == 0) return *raw + units;
  const double v =
      profiles::eds::from_raw(p.type, static_cast<std::uint16_t>(p.size * 8), little_endian(data));
  const double shown = (v + p.offset) * p.multiplier * p.base / p.divisor;
  return fmt::format("{:.{}f}{} (raw {})", shown, p.decimals, units, *raw);
}

}  // namespace

CLI::App* add_param(CLI::App& app, ParamArgs& args) {
  auto* cmd = app.add_subcommand(
      "param",
      "Read a device's parameter, or write it and read it back, by its name in the device's EDS "
      "(Parameter object, class 0x0F), through its bridge's explicit gateway.");
  cmd->add_option("NODE", args.node, "The node: its MAC ID (0..63) or its name")->required();
  cmd->add_option("PARAM", args.param,
                  "The parameter: its name in the EDS, or ParamN where names repeat")
      ->required();
  cmd->add_option("VALUE", args.value, "A value to write (as the device holds it: 5, -2.5, 0x81)");
  cmd->add_option("--eds", args.eds, "The device's EDS file (the one its node is configured with)")
      ->required()
      ->type_name("FILE");
  cmd->footer(kParamNote);
  return cmd;
}

Exit run_param(const GlobalOptions& o, const ParamArgs& args) {
  // Everything typed is checked before anything is sent.
  auto ref = parse_node(args.node);
  if (!ref) throw CommandError(Exit::kUsage, ref.error());
  const profiles::eds::EdsFile file = read_eds(args.eds);
  std::string why;
  auto found = profiles::eds::find_param(file, args.param, args.eds, &why);
  if (!found) throw CommandError(Exit::kUsage, why);
  const profiles::eds::Param& p = **found;
  std::optional<devicenet::AttributeSetting> write;
  if (!args.value.empty()) {
    char* end = nullptr;
    const double v = std::strtod(args.value.c_str(), &end);
    if (end != args.value.c_str() + args.value.size() || !std::isfinite(v)) {
      throw CommandError(Exit::kUsage, fmt::format("\"{}\" is not a number", args.value));
    }
    auto s = profiles::eds::parameter_setting(file, {fmt::format("Param{}", p.number), v}, args.eds,
                                              &why);
    if (!s) throw CommandError(Exit::kUsage, why);
    write = std::move(*s);
  }
  install_interrupt_handlers();

  Client client = make_client(o);
  const NodeKey key = find_port(client, o, *ref);
  const std::string name = node_name(key.rack, key.port, key.mac);
  Requester requester(client, requester_name(), key.rack);
  const devicenet::AttributeSetting target = target_of(p);
  const auto exchange = [&](std::uint8_t service, std::vector<std::uint8_t> data) {
    ExplicitExchange x;
    x.rack = key.rack;
    x.port = key.port;
    x.mac = key.mac;
    x.service = service;
    x.class_id = target.class_id;
    x.instance_id = target.instance_id;
    x.attribute = target.attribute;
    x.request_data = std::move(data);
    if (!requester.execute(client, x, deadline_after(o.timeout()))) {
      throw CommandError(Exit::kNotFound,
                         fmt::format("{}: no reply from the bridge of rack \"{}\" within {:g} s",
                                     name, key.rack, o.timeout_seconds));
    }
    if (!x.succeeded()) {
      throw CommandError(Exit::kFailed,
                         fmt::format("{}: {} of Param{} \"{}\" ({}) failed: {}", name,
                                     service_text(service), p.number, p.name,
                                     cip::describe(cip::EPath{target.class_id, target.instance_id,
                                                              std::nullopt, target.attribute}),
                                     failure_text(x)));
    }
    return x;
  };
  if (write) {
    // Not on a node of another identity: another device's EDS names other
    // attributes, and other types.
    if (const auto* node = client.node(key)) {
      const auto& n = *node->data;
      const auto& d = file.device;
      if (n.vendor_id != 0 && (n.vendor_id != d.vendor_code || n.product_type != d.product_type ||
                               n.product_code != d.product_code)) {
        throw CommandError(
            Exit::kUsage,
            fmt::format(
                "{} is vendor {}, product type {}, product code {}; {} describes vendor {}, "
                "product type {}, product code {}: not written",
                name, n.vendor_id, n.product_type, n.product_code, args.eds, d.vendor_code,
                d.product_type, d.product_code));
      }
    }
    (void)exchange(cip::code(cip::Service::kSetAttributeSingle), write->value);
  }
  ExplicitExchange read;
  try {
    read = exchange(cip::code(cip::Service::kGetAttributeSingle), {});
  } catch (const CommandError& e) {
    if (!write) throw;
    throw CommandError(e.code(), fmt::format("written; reading it back failed: {}", e.what()));
  }
  const Bytes data(read.data.data(), read.data.size());
  // A device that rounds or bounds what it was given holds something else.
  const bool holds_written =
      !write || std::equal(data.begin(), data.end(), write->value.begin(), write->value.end());

  if (o.json) {
    JsonWriter out;
    out.begin_object()
        .field("rack", key.rack)
        .field("port", key.port)
        .field("mac", unsigned{key.mac})
        .field("param", p.number)
        .field("name", p.name)
        .field("type", p.type.name)
        .field("units", p.units)
        .field("written", write.has_value())
        .field("data", hex_bytes(data));
    out.field("holds_written", holds_written);
    out.key("value");
    if (const auto raw = raw_text(p, data)) {
      out.number_text(*raw);
    } else {
      out.null();  // not a finite number of the parameter's size
    }
    out.end_object();
    print(out.str() + "\n");
  } else {
    print(fmt::format("{}: Param{} \"{}\" = {} ({}, {}){}\n", name, p.number, p.name,
                      value_text(p, data), p.type.name, hex_bytes(data),
                      write ? " (written, read back)" : ""));
  }
  if (!holds_written) {
    std::fputs(fmt::format("dnbctl: {}: Param{} was written [{}] but holds [{}]\n", name, p.number,
                           hex_bytes(write->value), hex_bytes(data))
                   .c_str(),
               stderr);
    return Exit::kFailed;
  }
  return Exit::kOk;
}

}  // namespace dnbridge::dnbctl
