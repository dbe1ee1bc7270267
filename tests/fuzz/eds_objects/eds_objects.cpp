// The objects of a simulated EDS-described device (adapters/sim/generic).
// Input: an explicit request message (service byte first, 8/8 body), run on
// a device of a small EDS with parameters of several types, an assembly of
// parameters, padding and a nested assembly. Properties: every request is
// answered, with a success response to its service or an error response;
// a parameter keeps its size whatever is set; the assembly data keeps its
// size.
#include <array>
#include <cstddef>
#include <cstdint>

#include "adapters/sim/generic/eds_objects.hpp"
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
  static sim::EdsObjects objects(*eds::parse(kEds).file, 1);
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
  FUZZ_CHECK(device().param_value(1).size() == 2);
  FUZZ_CHECK(device().param_value(3).size() == 4);
  FUZZ_CHECK(device().assembly_data(1).size() == 5);
  return 0;
}
