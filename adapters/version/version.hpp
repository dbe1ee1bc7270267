#pragma once

#include <string>
#include <string_view>

// What a program of the product says it is: dnbridge, dnbridge-sim, dnbctl,
// cdn127-sim and dnbridge-demo answer --version with text(their name).
namespace dnbridge::version {

// The product's version, as the Debian package gives it: "0.1.0".
std::string_view number();

// The source revision built from, as `git describe --always --dirty` gave it
// at build time, or "unknown" when built outside a git checkout.
std::string_view revision();

// The Cyclone DDS version built against: "0.10.2".
std::string_view cyclonedds();

enum class Dds { kUsed, kNotUsed };

// The first line "PROGRAM VERSION", for scripts to read; then the revision
// and, for a program that talks DDS, the Cyclone DDS it was built with:
//   dnbctl 0.1.0
//   revision 40f01f30f1a4
//   Cyclone DDS 0.10.2
std::string text(std::string_view program, Dds dds);

}  // namespace dnbridge::version
