// CIP SHORT_STRING, STRING and fixed strings. Input: the encoded bytes; the
// readers are also run back to back over the whole input.
// Properties: a string that decodes re-encodes to the very same bytes; the
// text is a view into the input; readers never move past the end and fail
// with an empty view; trim_padding only removes trailing NULs and spaces.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "bridge/cip/data_types.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::cip;

namespace {

bool inside(std::string_view text, Bytes whole) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(text.data());
  return text.empty() || (p >= whole.data() && p + text.size() <= whole.data() + whole.size());
}

template <class Decode, class Encode>
void round_trip(Bytes input, Decode decode, Encode encode) {
  auto text = decode(input);
  if (!text) return;
  FUZZ_CHECK(inside(*text, input));
  std::array<std::uint8_t, 2 + kMaxStringLength> buf{};
  auto n = encode(*text, MutableBytes(buf));
  FUZZ_CHECK(n.ok() && *n == input.size());
  for (std::size_t i = 0; i < input.size(); ++i) FUZZ_CHECK(buf[i] == input[i]);
  FUZZ_CHECK(!encode(*text, MutableBytes(buf.data(), input.size() - 1)).ok());
}

void check_trim(std::string_view text) {
  const std::string_view t = trim_padding(text);
  FUZZ_CHECK(t.size() <= text.size());
  FUZZ_CHECK(text.substr(0, t.size()) == t);
  for (char c : text.substr(t.size())) FUZZ_CHECK(c == '\0' || c == ' ');
  if (!t.empty()) FUZZ_CHECK(t.back() != '\0' && t.back() != ' ');
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Bytes input(data, size);
  round_trip(input, decode_short_string, encode_short_string);
  round_trip(input, decode_string, encode_string);

  // Readers as a structure decoder uses them: kind chosen by the byte before.
  ByteReader r(input);
  while (r.ok() && !r.at_end()) {
    const std::uint8_t kind = r.u8();
    const std::size_t before = r.consumed();
    std::string_view text;
    switch (kind % 3) {
      case 0:
        text = read_short_string(r);
        break;
      case 1:
        text = read_string(r);
        break;
      default:
        text = read_fixed_string(r, kind / 3U);
        break;
    }
    FUZZ_CHECK(inside(text, input));
    FUZZ_CHECK(r.consumed() >= before);
    if (!r.ok()) FUZZ_CHECK(text.empty());
    check_trim(text);
  }
  return 0;
}
