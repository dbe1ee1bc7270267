// The Assembly object's member list (cip/assembly.hpp). Input: attribute 2's
// bytes. Properties: a list that decodes encodes back to exactly the input;
// its members' paths are decoded exactly when their bytes are a logical
// path; describe() never fails.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "bridge/cip/assembly.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::cip;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto members = decode_member_list(Bytes(data, size));
  if (!members) return 0;
  FUZZ_CHECK(encode_member_list(*members) == std::vector<std::uint8_t>(data, data + size));
  for (const auto& m : *members) {
    const bool logical =
        !m.path_bytes.empty() && decode_epath(Bytes(m.path_bytes.data(), m.path_bytes.size())).ok();
    FUZZ_CHECK(m.path.has_value() == logical);
    FUZZ_CHECK(!describe(m).empty());
  }
  return 0;
}
