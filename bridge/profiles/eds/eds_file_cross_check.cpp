// Reader: what the sections say of each other, once each is read: assembly
// cycles, and the inputs, outputs, parameters and assemblies an entry names.
#include <fmt/format.h>

#include <algorithm>
#include <set>
#include <utility>
#include <vector>

#include "bridge/profiles/eds/eds_file_internal.hpp"

namespace dnbridge::profiles::eds::eds_file_detail {

// AssemN members that lead back to an assembly they are in.
void Reader::assembly_cycles(const EdsFile& f) {
  const auto find = [&](unsigned n) -> const Assembly* {
    for (const Assembly& a : f.assemblies) {
      if (a.number == n) return &a;
    }
    return nullptr;
  };
  for (const Assembly& start : f.assemblies) {
    // Depth-first along AssemN members, as far as there are assemblies.
    std::vector<std::pair<const Assembly*, std::size_t>> stack{{&start, 0}};
    std::set<unsigned> on_path{start.number};
    bool found = false;
    while (!stack.empty() && !found) {
      auto& [a, next] = stack.back();
      if (next == a->members.size()) {
        on_path.erase(a->number);
        stack.pop_back();
        continue;
      }
      const Member& m = a->members[next++];
      if (m.kind != Member::Kind::kAssembly) continue;
      if (m.number == start.number) {
        error(start.line, fmt::format("Assem{} ({}) contains itself through its members",
                                      start.number, start.name));
        failed_.insert(entry_key(fmt::format("Assem{}", start.number)));
        found = true;
        continue;
      }
      const Assembly* nested = find(m.number);
      if (nested != nullptr && on_path.insert(nested->number).second) {
        stack.emplace_back(nested, 0);
      }
    }
  }
}

void Reader::cross_check(const EdsFile& f) {
  assembly_cycles(f);
  for (const auto& c : f.io.connections) {
    if (c.input != 0 && f.io.input(c.input) == nullptr &&
        !has_failed(fmt::format("Input{}", c.input))) {
      error(c.line,
            fmt::format("{} connection: Input{} is not in [IO_Info]", to_string(c.kind), c.input));
    }
    if (c.output != 0 && f.io.output(c.output) == nullptr &&
        !has_failed(fmt::format("Output{}", c.output))) {
      error(c.line, fmt::format("{} connection: Output{} is not in [IO_Info]", to_string(c.kind),
                                c.output));
    }
  }
  for (ConnectionKind k : kConnectionKinds) {
    const std::string_view info = k == ConnectionKind::kPoll     ? "PollInfo"
                                  : k == ConnectionKind::kStrobe ? "StrobeInfo"
                                  : k == ConnectionKind::kCyclic ? "CyclicInfo"
                                                                 : "COSInfo";
    if (f.io.defaults.has(k) && f.io.connection(k) == nullptr && !has_failed(info)) {
      error(defaults_line_, fmt::format("[IO_Info] Default names {}, which no {} entry describes",
                                        to_string(k), info));
    }
  }
  for (const auto* list : {&f.io.inputs, &f.io.outputs}) {
    for (const IoData& d : *list) {
      const Assembly* a = f.assembly_at(d.path);
      if (a != nullptr && (a->bits || !a->members.empty()) && a->size_bits() != d.size * 8u) {
        error(d.line, fmt::format("{} ({}) is {} bytes, the Assem{} it names is {} bits",
                                  list == &f.io.inputs ? "an input" : "an output", d.name, d.size,
                                  a->number, a->size_bits()));
      }
    }
  }
  for (const Assembly& a : f.assemblies) {
    for (const Member& m : a.members) {
      if (m.kind == Member::Kind::kParam) {
        const Param* p = f.param(m.number);
        if (p == nullptr && has_failed(fmt::format("Param{}", m.number))) {
          // Said where the parameter is.
        } else if (p == nullptr) {
          error(a.line, fmt::format("Assem{} ({}): member Param{} is not in [Params]", a.number,
                                    a.name, m.number));
        } else if (p->type.size != 0 && m.bits > p->size * 8u) {
          error(a.line, fmt::format("Assem{} ({}): member Param{} ({}) is {} bits, the "
                                    "parameter {} ({} bits)",
                                    a.number, a.name, m.number, p->name, m.bits, p->type.name,
                                    p->size * 8u));
        }
      } else if (m.kind == Member::Kind::kAssembly &&
                 !has_failed(fmt::format("Assem{}", m.number)) &&
                 std::none_of(f.assemblies.begin(), f.assemblies.end(),
                              [&](const Assembly& b) { return b.number == m.number; })) {
        error(a.line, fmt::format("Assem{} ({}): member Assem{} is not in [Assembly]", a.number,
                                  a.name, m.number));
      }
    }
  }
}

}  // namespace dnbridge::profiles::eds::eds_file_detail
