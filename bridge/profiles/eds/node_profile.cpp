#include "bridge/profiles/eds/node_profile.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <set>
#include <string_view>
#include <utility>

#include "bridge/cip/assembly.hpp"
#include "bridge/cip/epath.hpp"
#include "bridge/common/closest.hpp"
#include "bridge/common/text.hpp"
#include "bridge/profiles/eds/member_check.hpp"

namespace dnbridge::profiles::eds {
namespace {

// Says why in `why` and returns `code`.
Errc explain(std::string* why, Errc code, std::string text) {
  if (why != nullptr) *why = std::move(text);
  return code;
}

std::string describe_data(const IoLayout& io, std::string_view what) {
  if (io.size == 0) return fmt::format("no {}", what);
  std::string text = fmt::format("{} {} B \"{}\"", what, io.size, io.name);
  if (!io.assembly.empty()) text += fmt::format(" = {}", io.assembly);
  return text;
}

// An assembly's member list on the device against its EDS entry.
class MemberListVerifier final : public devicenet::AttributeVerifier {
 public:
  MemberListVerifier(std::shared_ptr<const EdsFile> file, const Assembly& assembly)
      : file_(std::move(file)), assembly_(assembly) {}

  std::vector<std::string> differences(Bytes reported) const override {
    auto members = cip::decode_member_list(reported);
    if (!members) {
      return {
          fmt::format("the device's member list does not decode ({})", members.error().message())};
    }
    return member_differences(*file_, assembly_, *members);
  }

  // What is compared: the assembly's size and members as the EDS gives them.
  std::string key() const override {
    std::string k = fmt::format("Assem{}:{}", assembly_.number, assembly_.size_bits());
    for (const Member& m : assembly_.members) {
      k += fmt::format(";{}/{}/{}/{}", m.bits, static_cast<int>(m.kind), m.number,
                       cip::describe(m.path));
      if (m.kind == Member::Kind::kParam) {
        if (const Param* p = file_->param(m.number)) k += "@" + cip::describe(p->link);
      }
    }
    return k;
  }

 private:
  std::shared_ptr<const EdsFile> file_;
  Assembly assembly_;
};

// The check of the member list of the assembly `data` names, when the EDS
// lists its members.
std::optional<devicenet::AttributeCheck> member_list_check(
    const std::shared_ptr<const EdsFile>& file, const IoData* data) {
  if (data == nullptr) return std::nullopt;
  const Assembly* a = file->assembly_at(data->path);
  if (a == nullptr || a->members.empty() || !a->path.instance_id || *a->path.instance_id > 0xFFFF) {
    return std::nullopt;
  }
  devicenet::AttributeCheck c;
  c.class_id = 4;
  c.instance_id = static_cast<std::uint16_t>(*a->path.instance_id);
  c.attribute = 2;
  c.name = fmt::format("Assembly {} member list (Assem{}{})", c.instance_id, a->number,
                       a->name.empty() ? "" : " " + a->name);
  c.verifier = std::make_shared<MemberListVerifier>(file, *a);
  return c;
}

}  // namespace

Result<const Param*> find_param(const EdsFile& file, std::string_view name, std::string_view list,
                                std::string* why) {
  const Param* p = file.param(name);
  if (const auto named = file.params_named(name); p == nullptr && named.size() > 1) {
    std::string numbers;
    for (unsigned n : named) numbers += fmt::format("{}Param{}", numbers.empty() ? "" : ", ", n);
    return explain(why, Errc::kMalformed,
                   fmt::format("{}: \"{}\" names {} parameters ({}): name one as ParamN", list,
                               name, named.size(), numbers));
  }
  if (p == nullptr) {
    std::vector<std::string_view> names;
    for (const auto& q : file.params) names.push_back(q.name);
    const auto near = closest(name, names, std::max<std::size_t>(2, name.size() / 4));
    return explain(why, Errc::kMalformed,
                   fmt::format("{}: the EDS has no parameter \"{}\"{}", list, name,
                               near ? fmt::format(" (did you mean \"{}\"?)", *near) : ""));
  }
  return p;
}

namespace {

// The attribute the parameter's link path names, as a setting without its
// value; nothing when the link path is not a class, instance and attribute
// within their ranges (none, a connection point).
std::optional<devicenet::AttributeSetting> linked_attribute(const Param& p) {
  const cip::EPath& link = p.link;
  if (!link.class_id || !link.instance_id || !link.attribute || link.connection_point ||
      *link.class_id > 0xFFFF || *link.instance_id > 0xFFFF || *link.attribute > 0xFF) {
    return std::nullopt;
  }
  devicenet::AttributeSetting s;
  s.class_id = static_cast<std::uint16_t>(*link.class_id);
  s.instance_id = static_cast<std::uint16_t>(*link.instance_id);
  s.attribute = static_cast<std::uint8_t>(*link.attribute);
  s.name = fmt::format("Param{} {}", p.number, p.name);
  return s;
}

}  // namespace

Result<devicenet::AttributeSetting> parameter_setting(const EdsFile& file,
                                                      const ParameterValue& given,
                                                      std::string_view list, std::string* why) {
  auto found = find_param(file, given.name, list, why);
  if (!found) return found.error();
  const Param* p = *found;
  const std::string label = fmt::format("{}: Param{} \"{}\"", list, p->number, p->name);
  if (p->read_only()) {
    return explain(why, Errc::kMalformed, fmt::format("{} is read only", label));
  }
  auto linked = linked_attribute(*p);
  if (!linked) {
    return explain(why, Errc::kUnsupported,
                   fmt::format("{} has no link path to an attribute (its link path: {})", label,
                               p->link.empty() ? "none" : "not class/instance/attribute"));
  }
  if (p->type.size == 0) {
    return explain(why, Errc::kUnsupported,
                   fmt::format("{} is a {}: only numbers are set", label, p->type.name));
  }
  if (!within_limits(p->minimum, p->maximum, given.value)) {
    return explain(why, Errc::kOutOfRange,
                   fmt::format("{}: {} is outside the EDS's limits {}", label, given.value,
                               limits_text(p->minimum, p->maximum)));
  }
  const auto bits = static_cast<std::uint16_t>(p->size * 8);
  const auto raw = to_raw(p->type, bits, given.value);
  if (!raw) {
    return explain(why, Errc::kOutOfRange,
                   fmt::format("{}: {} is not a {} value", label, given.value, p->type.name));
  }
  // The limits hold for the value as the device gets it, too (a REAL in
  // single precision).
  if (!within_limits(p->minimum, p->maximum, from_raw(p->type, bits, *raw))) {
    return explain(why, Errc::kOutOfRange,
                   fmt::format("{}: {} is outside the EDS's limits {}", label, given.value,
                               limits_text(p->minimum, p->maximum)));
  }
  for (unsigned i = 0; i < p->size; ++i) {
    linked->value.push_back(static_cast<std::uint8_t>(*raw >> (8 * i)));
  }
  return std::move(*linked);
}

namespace {

// The EDS entries a node on `connection` uses (node_io()).
struct IoEntries {
  const IoData* input = nullptr;
  const IoData* output = nullptr;
};

Result<IoEntries> io_entries(const EdsFile& file, ConnectionKind connection, std::string* why) {
  const auto offered = [&](ConnectionKind kind) -> Result<const ConnectionInfo*> {
    if (const ConnectionInfo* c = file.io.connection(kind)) return c;
    std::string list;
    for (const auto& o : file.io.connections) {
      list += fmt::format("{}{}", list.empty() ? "" : ", ", to_string(o.kind));
    }
    return explain(
        why, Errc::kUnsupported,
        fmt::format("the EDS offers no {} connection (it offers: {}){}", to_string(kind),
                    list.empty() ? "none" : list,
                    kind == connection ? ""
                                       : fmt::format(": a node on {} has its outputs and keeps its "
                                                     "connections on a poll connection beside it",
                                                     to_string(connection))));
  };
  auto c = offered(connection);
  if (!c) return c.error();
  IoEntries e;
  e.input = (*c)->input != 0 ? file.io.input((*c)->input) : nullptr;
  const ConnectionInfo* out = *c;
  if (connection != ConnectionKind::kPoll) {
    if (connection == ConnectionKind::kStrobe && (*c)->output != 0) {
      return explain(why, Errc::kUnsupported,
                     fmt::format("the EDS's bit-strobe connection consumes Output{}: dnbridge's "
                                 "master sends every strobe bit as 0, and takes outputs on the "
                                 "poll connection only",
                                 (*c)->output));
    }
    auto poll = offered(ConnectionKind::kPoll);
    if (!poll) return poll.error();
    out = *poll;
    // The poll connection answers with the same input (one input per node).
    if (e.input && e.input->carried_by.bits != 0 &&
        !e.input->carried_by.has(ConnectionKind::kPoll)) {
      return explain(why, Errc::kUnsupported,
                     fmt::format("Input{} (\"{}\") is carried by {} only (EDS line {}): a "
                                 "node on {} is polled for the same input beside it",
                                 e.input->number, e.input->name, to_string(e.input->carried_by),
                                 e.input->line, to_string(connection)));
    }
  }
  e.output = out->output != 0 ? file.io.output(out->output) : nullptr;
  return e;
}

NodeIo layouts_of(const EdsFile& file, const IoEntries& e) {
  NodeIo io;
  if (e.input) io.produced = layout_of(file, *e.input);
  if (e.output) io.consumed = layout_of(file, *e.output);
  return io;
}

std::optional<devicenet::InputKind> input_kind(ConnectionKind k) {
  switch (k) {
    case ConnectionKind::kChangeOfState:
      return devicenet::InputKind::kChangeOfState;
    case ConnectionKind::kCyclic:
      return devicenet::InputKind::kCyclic;
    case ConnectionKind::kStrobe:
      return devicenet::InputKind::kBitStrobe;
    case ConnectionKind::kPoll:
      break;
  }
  return std::nullopt;
}

}  // namespace

Result<NodeIo> node_io(const EdsFile& file, ConnectionKind connection, std::string* why) {
  auto e = io_entries(file, connection, why);
  if (!e) return e.error();
  return layouts_of(file, *e);
}

Result<devicenet::NodeProfile> make_node_profile(const std::shared_ptr<const EdsFile>& shared,
                                                 const EdsNode& node, std::string* why) {
  const EdsFile& file = *shared;
  auto entries = io_entries(file, node.connection, why);
  if (!entries) return entries.error();
  const IoEntries& e = *entries;
  const NodeIo io = layouts_of(file, e);
  if (node.connection == ConnectionKind::kStrobe &&
      io.produced.size > devicenet::kMaxStrobeResponse) {
    return explain(why, Errc::kUnsupported,
                   fmt::format("the EDS's bit-strobe input is {} bytes: a bit-strobe response "
                               "carries at most {}",
                               io.produced.size, devicenet::kMaxStrobeResponse));
  }
  if (node.safe_state_of_device && !node.safe_state.empty()) {
    return explain(why, Errc::kMalformed,
                   "safe_state_parameters: given with safe_state = \"device\" (the device's own)");
  }
  if (io.consumed.size > 0 && node.safe_state.empty() && !node.safe_state_of_device) {
    return explain(
        why, Errc::kMalformed,
        fmt::format("the node has outputs ({}) and no safe state: give the parameters that set "
                    "their fault and idle actions (safe_state_parameters), or safe_state = "
                    "\"device\" where the device's maker fixes them",
                    describe_data(io.consumed, "output")));
  }

  devicenet::NodeProfile p;
  p.identity = {file.device.vendor_code, file.device.product_type, file.device.product_code};
  std::set<unsigned> seen;
  const auto add = [&](const std::vector<ParameterValue>& list, std::string_view label) -> Status {
    for (const ParameterValue& v : list) {
      auto s = parameter_setting(file, v, label, why);
      if (!s) return s.error();
      const Param* param = file.param(v.name);
      if (!seen.insert(param->number).second) {
        return explain(
            why, Errc::kMalformed,
            fmt::format("{}: Param{} \"{}\" is given twice", label, param->number, param->name));
      }
      p.settings.push_back(std::move(*s));
    }
    return {};
  };
  if (auto s = add(node.parameters, "parameters"); !s) return s.error();
  if (auto s = add(node.safe_state, "safe_state_parameters"); !s) return s.error();
  if (node.safe_state_of_device) {
    for (const Param* param : device_safe_state(file, node).read) {
      p.settings.push_back(*kept_setting(*param));
    }
  }

  // On change of state, cyclic or bit-strobe the poll response carries the
  // same data as the input connection's messages.
  if (e.input) p.produced_path = cip::encoded(e.input->path);
  if (e.output) p.consumed_path = cip::encoded(e.output->path);
  for (const IoData* d : {e.input, e.output}) {
    if (auto check = member_list_check(shared, d)) p.checks.push_back(std::move(*check));
  }
  p.produced_size = io.produced.size;
  p.consumed_size = io.consumed.size;
  if (const auto kind = input_kind(node.connection)) {
    devicenet::InputConnection in;
    in.kind = *kind;
    if (*kind != devicenet::InputKind::kBitStrobe) {
      in.acknowledged = node.acknowledged;
      in.expected_packet_rate = node.heartbeat;
    }
    if (*kind == devicenet::InputKind::kChangeOfState) in.inhibit = node.inhibit;
    in.produced_path = p.produced_path;
    in.produced_size = io.produced.size;
    p.input_connection = std::move(in);
  }
  p.format_description = fmt::format("{}, {}", describe_data(io.produced, "input"),
                                     describe_data(io.consumed, "output"));
  return p;
}

namespace {

// A parameter whose name speaks of a fault or an idle state ("fault",
// "idle", any case).
bool of_safe_state(const Param& p) {
  const std::string name = to_lower(p.name);
  return name.find("fault") != std::string::npos || name.find("idle") != std::string::npos;
}

}  // namespace

std::vector<const Param*> safe_state_left_to_device(const EdsFile& file, const EdsNode& node) {
  const auto set = [&](const Param& p) {
    for (const auto* list : {&node.parameters, &node.safe_state}) {
      for (const ParameterValue& v : *list) {
        if (file.param(v.name) == &p) return true;
      }
    }
    return false;
  };
  std::vector<const Param*> left;
  for (const Param& p : file.params) {
    if (p.read_only() || p.link.empty() || p.type.size == 0) continue;
    if (of_safe_state(p) && !set(p)) left.push_back(&p);
  }
  return left;
}

DeviceSafeState device_safe_state(const EdsFile& file, const EdsNode& node) {
  DeviceSafeState d;
  for (const Param& p : file.params) {
    if (!of_safe_state(p)) continue;
    const bool given =
        std::any_of(node.parameters.begin(), node.parameters.end(),
                    [&](const ParameterValue& v) { return file.param(v.name) == &p; });
    if (given) {
      d.written.push_back(&p);
    } else {
      (kept_setting(p) ? d.read : d.unread).push_back(&p);
    }
  }
  return d;
}

std::optional<devicenet::AttributeSetting> kept_setting(const Param& p) {
  auto s = linked_attribute(p);
  if (!s || (p.size != 1 && p.size != 2 && p.size != 4)) {
    return std::nullopt;  // kept values are read as 1, 2 or 4 byte integers
  }
  s->value.assign(p.size, 0);
  s->keep_device_value = true;
  s->device_value_max = p.size == 4 ? 0xFFFFFFFFu : (1u << (8 * p.size)) - 1;
  return s;
}

}  // namespace dnbridge::profiles::eds
