// The objects of a simulated EDS-described device (adapters/sim/generic).
// Input: an explicit request message (service byte first, 8/8 body), run on
// a device of a small EDS with parameters of several types, an assembly of
// parameters, padding and a nested assembly. Properties: every request is
// answered, with a success response to its service or an error response;
// no Set leaves a parameter outside its limits or not a number (REALs by
// their limits as REALs); the assembly data keeps its size.
#include "adapters/sim/generic/eds_objects.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;

namespace {

constexpr const char* kEds = R"(
[Device]
VendCode = 65001; ProdType = 7; ProdCode = 9; MajRev = 1; MinRev = 2; ProdName = "fuzz";
[Params]
Param1 = 0, 6, "20 0F 24 01 30 01", 0, 0xC3, 2, "a", "", "", -100, 100, 5;
Param2 = 0, 0, , 0x10, 0xC6, 1, "b", "", "", 0, 200, 1;
Param3 = 0, 0, , 0, 0xCA, 4, "c", "", "", -1.5, 1.5, 0.25;
Param4 = 0, 0, , 0, 0xC8, 4, "d", "", "", 0, 4000000000, 7;
[Assembly]
Assem1 = "x", "20 04 24 01 30 03", 40, 0, , , 16, Param1, 4, , 4, Param2, 16, Assem2;
Assem2 = "y", , 16, 0, , , 16, Param1;
)";

sim::EdsObjects& device() {
  static sim::EdsObjects objects(*profiles::eds::parse(kEds).file, 1);
  return objects;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto request = devicenet::decode_request(Bytes(data, size), devicenet::BodyFormat::k8_8);
  if (!request) return 0;
  std::array<std::uint8_t, devicenet::kMaxExplicitMessage> out{};
  const std::size_t n = device().execute(*request, MutableBytes(out));
  FUZZ_CHECK(n >= 1);
  FUZZ_CHECK(out[0] == (request->service | 0x80) || (out[0] == 0x94 && n == 3));
  // No Set leaves a value outside its limits, nor one that is not a number.
  for (unsigned number = 1; number <= 4; ++number) {
    const profiles::eds::Param* p = device().file().param(number);
    const auto v = device().param_number(number);
    FUZZ_CHECK(p != nullptr && v.has_value() && std::isfinite(*v));
    const auto limit = [&](double l) {
      return p->type.is_float && p->size == 4 ? double{static_cast<float>(l)} : l;
    };
    FUZZ_CHECK(!p->minimum || *v >= limit(*p->minimum));
    FUZZ_CHECK(!p->maximum || *v <= limit(*p->maximum));
  }
  FUZZ_CHECK(device().assembly_data(1).size() == 5);
  return 0;
}
