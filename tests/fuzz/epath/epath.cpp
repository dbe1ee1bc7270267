// CIP EPATH of logical segments. Input: the path bytes.
// Properties: a path that decodes encodes (in every minimum format) to
// encoded_size() bytes that decode to the same path; the smallest encoding is
// never longer than the input; an encoder refuses a buffer one byte short.
#include "bridge/cip/epath.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::cip;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto path = decode_epath(Bytes(data, size));
  if (!path) return 0;
  FUZZ_CHECK(path->empty() == (size == 0));
  for (const LogicalFormat f :
       {LogicalFormat::k8Bit, LogicalFormat::k16Bit, LogicalFormat::k32Bit}) {
    std::array<std::uint8_t, 32> buf{};
    const std::size_t need = encoded_size(*path, f);
    FUZZ_CHECK(need <= buf.size());
    if (f == LogicalFormat::k8Bit) FUZZ_CHECK(need <= size);
    auto n = encode(*path, MutableBytes(buf), f);
    FUZZ_CHECK(n.ok() && *n == need);
    if (need > 0) FUZZ_CHECK(!encode(*path, MutableBytes(buf.data(), need - 1), f).ok());
    auto again = decode_epath(Bytes(buf.data(), *n));
    FUZZ_CHECK(again.ok());
    FUZZ_CHECK(*again == *path);
  }
  return 0;
}
