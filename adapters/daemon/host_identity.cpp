#include "adapters/daemon/host_identity.hpp"

#include <unistd.h>

#include <array>
#include <fstream>

namespace dnbridge::daemon {

std::string read_host_id() {
  for (const char* path : {"/etc/machine-id", "/var/lib/dbus/machine-id"}) {
    std::ifstream in(path);
    std::string id;
    if (in && std::getline(in, id) && !id.empty()) return id;
  }
  std::array<char, 256> name{};
  if (::gethostname(name.data(), name.size() - 1) == 0) return std::string(name.data());
  return {};
}

std::uint32_t derived_master_serial(std::string_view host_id, std::string_view port) {
  std::uint32_t h = 2166136261u;
  const auto mix = [&h](std::string_view s) {
    for (const char c : s) {
      h ^= static_cast<std::uint8_t>(c);
      h *= 16777619u;
    }
  };
  mix(host_id);
  mix("/");
  mix(port);
  return h;
}

}  // namespace dnbridge::daemon
