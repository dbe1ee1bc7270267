// dnbctl eds check FILE: reads an EDS file as the bridge will, and says
// what it found in it, or every problem with its line.
#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/json.hpp"
#include "bridge/cip/assembly.hpp"
#include "bridge/profiles/eds/eds_file.hpp"

namespace dnbridge::dnbctl {
namespace {

using profiles::eds::ConnectionKind;
using profiles::eds::EdsFile;
using profiles::eds::Member;
using profiles::eds::Problem;

std::string read_text(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw CommandError(Exit::kUsage, fmt::format("cannot read {}: it is a directory", path));
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    throw CommandError(Exit::kUsage,
                       fmt::format("cannot read {}: {}", path,
                                   error != 0 ? std::strerror(error) : "cannot be opened"));
  }
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string io_data_text(const EdsFile& f, const profiles::eds::IoData& d, const char* what) {
  std::string text = fmt::format("{} {} ({} byte{}, \"{}\"", what, d.number, d.size,
                                 d.size == 1 ? "" : "s", d.name);
  if (const profiles::eds::Assembly* a = f.assembly_at(d.path)) {
    text += fmt::format(", assembly {}", a->number);
  } else {
    text += ", " + cip::describe(d.path);
  }
  return text + ")";
}

std::string member_text(const EdsFile& f, const Member& m) {
  const std::string bits = fmt::format("{} bit{}", m.bits, m.bits == 1 ? "" : "s");
  switch (m.kind) {
    case Member::Kind::kPadding:
      return bits + " padding";
    case Member::Kind::kPath:
      return bits + " " + cip::describe(m.path);
    case Member::Kind::kParam: {
      const profiles::eds::Param* p = f.param(m.number);
      return fmt::format("{} Param{} ({})", bits, m.number, p ? p->name : "?");
    }
    case Member::Kind::kAssembly:
      return fmt::format("{} Assem{}", bits, m.number);
  }
  return "?";
}

std::string limit(const std::optional<double>& v) { return v ? fmt::format("{}", *v) : "-"; }

std::string summary(const std::string& path, const EdsFile& f) {
  std::string out =
      fmt::format("{}: {}", path, f.description.empty() ? "(no DescText)" : f.description);
  if (!f.revision.empty()) out += fmt::format(" (file revision {})", f.revision);
  out += "\n";
  const auto& d = f.device;
  out += fmt::format(
      "device: vendor {} ({}), product type {} ({}), product code {}, revision {}.{}, \"{}\"{}\n",
      d.vendor_code, d.vendor_name, d.product_type, d.product_type_name, d.product_code,
      d.major_revision, d.minor_revision, d.product_name,
      d.catalog.empty() ? "" : fmt::format(" ({})", d.catalog));
  if (f.io.connections.empty()) {
    out += "I/O connections: none (explicit messages only)\n";
  } else {
    out += "I/O connections:\n";
    for (ConnectionKind k : profiles::eds::kConnectionKinds) {
      const profiles::eds::ConnectionInfo* c = f.io.connection(k);
      if (c == nullptr) continue;
      out += fmt::format("  {}{}:", profiles::eds::to_string(k),
                         f.io.defaults.has(k) ? " (default)" : "");
      const profiles::eds::IoData* in = f.io.input(c->input);
      const profiles::eds::IoData* o = f.io.output(c->output);
      out += in ? " produces " + io_data_text(f, *in, "input") : " produces nothing";
      out += o ? ", consumes " + io_data_text(f, *o, "output") : ", consumes nothing";
      out += "\n";
    }
  }
  out += fmt::format("parameters: {}\n", f.params.size());
  for (const auto& p : f.params) {
    out += fmt::format("  {:>3} {}: {}{}, {}..{}, default {}{}\n", p.number, p.name, p.type.name,
                       p.units.empty() ? "" : " in " + p.units, limit(p.minimum), limit(p.maximum),
                       limit(p.default_value), p.read_only() ? ", read only" : "");
  }
  out += fmt::format("assemblies: {}\n", f.assemblies.size());
  for (const auto& a : f.assemblies) {
    out += fmt::format("  {:>3} \"{}\": {} bits", a.number, a.name, a.size_bits());
    for (std::size_t i = 0; i < a.members.size(); ++i) {
      out += (i == 0 ? ": " : ", ") + member_text(f, a.members[i]);
    }
    out += "\n";
  }
  return out;
}

std::string json(const std::string& path, const profiles::eds::Parsed& parsed) {
  JsonWriter w;
  w.begin_object().field("file", path).field("valid", parsed.file.has_value());
  w.key("problems").begin_array();
  for (const Problem& p : parsed.problems) {
    w.begin_object()
        .field("line", static_cast<std::uint64_t>(p.line))
        .field("severity", p.severity == Problem::Severity::kError ? "error" : "warning")
        .field("message", p.message)
        .end_object();
  }
  w.end_array();
  w.field("errors", static_cast<std::uint64_t>(parsed.errors));
  w.field("problems_not_shown", static_cast<std::uint64_t>(parsed.not_shown));
  if (parsed.file) {
    const EdsFile& f = *parsed.file;
    const auto& d = f.device;
    w.key("device")
        .begin_object()
        .field("vendor_code", unsigned{d.vendor_code})
        .field("vendor_name", d.vendor_name)
        .field("product_type", unsigned{d.product_type})
        .field("product_code", unsigned{d.product_code})
        .field("major_revision", unsigned{d.major_revision})
        .field("minor_revision", unsigned{d.minor_revision})
        .field("product_name", d.product_name)
        .end_object();
    w.key("connections").begin_array();
    for (const auto& c : f.io.connections) {
      w.begin_object()
          .field("kind", profiles::eds::to_string(c.kind))
          .field("default", f.io.defaults.has(c.kind));
      const profiles::eds::IoData* in = f.io.input(c.input);
      const profiles::eds::IoData* o = f.io.output(c.output);
      w.key("input_bytes");
      in ? w.value(unsigned{in->size}) : w.null();
      w.key("output_bytes");
      o ? w.value(unsigned{o->size}) : w.null();
      w.end_object();
    }
    w.end_array();
    w.key("parameters").begin_array();
    for (const auto& p : f.params) {
      w.begin_object()
          .field("number", p.number)
          .field("name", p.name)
          .field("type", p.type.name)
          .field("units", p.units)
          .field("read_only", p.read_only())
          .end_object();
    }
    w.end_array();
    w.key("assemblies").begin_array();
    for (const auto& a : f.assemblies) {
      w.begin_object()
          .field("number", a.number)
          .field("name", a.name)
          .field("bits", static_cast<std::uint64_t>(a.size_bits()));
      w.key("members").begin_array();
      for (const auto& m : a.members) w.value(member_text(f, m));
      w.end_array().end_object();
    }
    w.end_array();
  }
  w.end_object();
  return w.str() + "\n";
}

}  // namespace

profiles::eds::EdsFile read_eds(const std::string& path) {
  profiles::eds::Parsed parsed = profiles::eds::parse(read_text(path));
  if (!parsed.file) {
    std::string problems;
    for (const Problem& p : parsed.problems) {
      if (p.severity == Problem::Severity::kError)
        problems += "\n" + profiles::eds::format_problem(path, p);
    }
    throw CommandError(Exit::kUsage,
                       fmt::format("{}: not usable, {} error{}{}", path, parsed.errors,
                                   parsed.errors == 1 ? "" : "s", problems));
  }
  return std::move(*parsed.file);
}

CLI::App* add_eds(CLI::App& app, EdsArgs& args) {
  auto* eds = app.add_subcommand("eds", "Electronic Data Sheets (EDS files) of DeviceNet devices");
  eds->require_subcommand(1);
  auto* check = eds->add_subcommand(
      "check",
      "Read an EDS file as the bridge reads it: what it describes (identity, I/O connections, "
      "parameters, assemblies), or each problem as FILE:LINE: error: ... on stderr (exit 1)");
  check->add_option("file", args.file, "The EDS file")->required()->type_name("FILE");
  return eds;
}

Exit run_eds(const GlobalOptions& options, const EdsArgs& args) {
  const profiles::eds::Parsed parsed = profiles::eds::parse(read_text(args.file));
  if (options.json) {
    print(json(args.file, parsed));
  } else {
    for (const Problem& p : parsed.problems) {
      std::fprintf(stderr, "%s\n", profiles::eds::format_problem(args.file, p).c_str());
    }
    if (parsed.not_shown > 0) {
      std::fprintf(stderr, "%s: %zu more problems not shown\n", args.file.c_str(),
                   parsed.not_shown);
    }
    if (parsed.file) print(summary(args.file, *parsed.file));
  }
  if (!parsed.file) {
    throw CommandError(Exit::kFailed, fmt::format("{}: not usable, {} error{}", args.file,
                                                  parsed.errors, parsed.errors == 1 ? "" : "s"));
  }
  return Exit::kOk;
}

}  // namespace dnbridge::dnbctl
