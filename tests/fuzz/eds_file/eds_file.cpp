// EDS files (bridge/profiles/eds). Input: the file's text.
// Properties: reading never fails hard; a file comes back exactly when no
// problem is an error, shown or not; every problem has a line within the text, in line
// order, at most kMaxProblems of them; what a file gives refers only to what
// it holds (each connection's input and output, each member's parameter,
// or one it left out with a warning).
#include "bridge/profiles/eds/eds_file.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::profiles::eds;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const Parsed parsed = parse(text);
  const auto lines = static_cast<std::uint32_t>(std::count(text.begin(), text.end(), '\n')) + 1;
  std::size_t errors = 0;
  std::uint32_t last = 0;
  FUZZ_CHECK(parsed.problems.size() <= kMaxProblems);
  for (const Problem& p : parsed.problems) {
    FUZZ_CHECK(p.line >= 1 && p.line <= lines);
    FUZZ_CHECK(p.line >= last);
    FUZZ_CHECK(!p.message.empty());
    last = p.line;
    errors += p.severity == Problem::Severity::kError ? 1 : 0;
  }
  FUZZ_CHECK(errors <= parsed.errors);
  FUZZ_CHECK(parsed.not_shown == 0 || parsed.problems.size() == kMaxProblems);
  // Errors are shown before any warning is.
  const bool warning_shown =
      std::any_of(parsed.problems.begin(), parsed.problems.end(),
                  [](const Problem& p) { return p.severity == Problem::Severity::kWarning; });
  FUZZ_CHECK(!warning_shown || errors == parsed.errors);
  FUZZ_CHECK(parsed.file.has_value() == (parsed.errors == 0));
  if (!parsed.file) return 0;
  const EdsFile& f = *parsed.file;
  for (const ConnectionInfo& c : f.io.connections) {
    FUZZ_CHECK(c.input == 0 || f.io.input(c.input) != nullptr);
    FUZZ_CHECK(c.output == 0 || f.io.output(c.output) != nullptr);
  }
  for (const Assembly& a : f.assemblies) {
    std::uint32_t bits = 0;
    for (const Member& m : a.members) {
      bits += m.bits;
      // A parameter left out (a warning says why) is named all the same.
      if (m.kind == Member::Kind::kParam) {
        FUZZ_CHECK(f.param(m.number) != nullptr || f.param_left_out(m.number));
      }
    }
    FUZZ_CHECK(!a.bits || a.members.empty() || *a.bits == bits);
    FUZZ_CHECK(a.size_bits() == (a.bits ? *a.bits : bits));
  }
  for (const Param& p : f.params) {
    FUZZ_CHECK(p.divisor != 0);
    FUZZ_CHECK(!p.minimum || !p.maximum || *p.minimum <= *p.maximum);
  }
  return 0;
}
