#include "bridge/rack/node_rack.hpp"

#include <fmt/format.h>

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
    case IdleCause::kCommanderSilent:
      return "idle: commander silent";
  }
  return "idle";
}

std::string NodeView::idle_text(bool command_in_force) const {
  if (command_in_force) return {};
  if (idle_cause == IdleCause::kCommanderSilent) {
    return fmt::format("idle: commander silent for {} ms",
                       std::chrono::duration_cast<milliseconds>(silent_for).count());
  }
  return std::string(to_string(idle_cause));
}

}  // namespace dnbridge::rack
