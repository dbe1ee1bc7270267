#include "bridge/rack/node_rack.hpp"

namespace dnbridge::rack {

std::string_view to_string(IdleCause cause) noexcept {
  switch (cause) {
    case IdleCause::kNoCommandYet:
      return "idle: no command yet";
    case IdleCause::kNoCommander:
      return "idle: no live commander";
    case IdleCause::kAfterLoss:
      return "idle: waiting for a new command after reconnection";
    case IdleCause::kReconfigured:
      return "idle: configured again after a reload, waiting for a new command";
  }
  return "idle";
}

}  // namespace dnbridge::rack
