// DeviceNet identifier, explicit header and fragment byte codecs. The input's
// first 4 bytes (little-endian, missing bytes 0) are a CAN identifier; every
// byte of the input is also tried as a header and a fragment byte.
// Properties: an identifier that decodes encodes back to itself; one that
// does not decode is outside 0..0x7EF; the header and fragment byte codecs
// are bijections on their byte.
#include "bridge/devicenet/wire/identifier.hpp"

#include <cstddef>
#include <cstdint>

#include "bridge/devicenet/wire/explicit_message.hpp"
#include "bridge/devicenet/wire/fragmentation.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::devicenet;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::uint32_t can_id = 0;
  for (std::size_t i = 0; i < size && i < 4; ++i)
    can_id |= static_cast<std::uint32_t>(data[i]) << (8 * i);

  for (const std::uint32_t id : {can_id, can_id & can::kMaxStandardId}) {
    auto decoded = decode_identifier(id);
    if (!decoded) {
      FUZZ_CHECK(id > 0x7EF);
      continue;
    }
    FUZZ_CHECK(id <= 0x7EF);
    auto encoded = encode_identifier(*decoded);
    FUZZ_CHECK(encoded.ok());
    FUZZ_CHECK(*encoded == id);
    auto again = decode_identifier(*encoded);
    FUZZ_CHECK(again.ok() && *again == *decoded);
  }

  for (std::size_t i = 0; i < size; ++i) {
    const ExplicitHeader h = decode_header(data[i]);
    FUZZ_CHECK(encode_header(h) == data[i]);
    const FragmentByte f = decode_fragment_byte(data[i]);
    FUZZ_CHECK(f.count <= 63);
    FUZZ_CHECK(encode_fragment_byte(f) == data[i]);
  }
  return 0;
}
