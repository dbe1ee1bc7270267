#pragma once
// An entity the bridge can run without when DDS Security does not grant it.
#include <optional>
#include <string_view>

#include "adapters/dds/entity.hpp"
#include "bridge/common/log.hpp"

namespace dnbridge::daemon {

// Makes `make()`'s entity, or nothing when DDS Security does not grant it
// (permissions signed before the service came): the bridge then runs
// without it, and says so once, naming `what`. Any other failure throws.
template <class Make>
auto unless_denied(Logger& log, std::string_view what, Make make)
    -> std::optional<decltype(make())> {
  try {
    return make();
  } catch (const dds::Error& e) {
    if (e.code() != DDS_RETCODE_NOT_ALLOWED_BY_SECURITY) throw;
    log.warn(
        "{}: not in this bridge's DDS Security permissions, so not offered (the site's "
        "make-site-pki.sh, run again, grants it): {}",
        what, e.what());
    return std::nullopt;
  }
}

}  // namespace dnbridge::daemon
