#include "adapters/version/version.hpp"

#include <dds/version.h>
#include <fmt/format.h>

namespace dnbridge::version {

std::string_view number() { return DNBRIDGE_VERSION; }

std::string_view cyclonedds() { return DDS_VERSION; }

std::string text(std::string_view program, Dds dds) {
  auto s = fmt::format("{} {}\nrevision {}", program, number(), revision());
  if (dds == Dds::kUsed) s += fmt::format("\nCyclone DDS {}", cyclonedds());
  return s;
}

}  // namespace dnbridge::version
