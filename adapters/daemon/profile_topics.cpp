#include "adapters/daemon/profile_topics.hpp"

#include <vector>

#include "adapters/daemon/samples.hpp"
#include "bridge/rack/device_rack.hpp"
#include "bridge/rack/pump_rack.hpp"

namespace dnbridge::daemon {

std::span<const ProfileTopics> bridge_profiles() {
  // The CDN127's topics are the bridge's reason to run: required. A device
  // described by its EDS is published where DDS Security grants its topics.
  static const std::vector<ProfileTopics> kProfiles = {
      topics_of<dnbridge_PumpState, rack::PumpView, dnbridge_PumpCommand>(
          rack::PumpProfile::kName, true, {&fill_pump_state, &fill_node_status, &command_of}),
      topics_of<dnbridge_DeviceState, rack::DeviceView, dnbridge_DeviceCommand>(
          rack::DeviceProfile::kName, false, {&fill_device_state, &fill_node_status, &command_of}),
  };
  return kProfiles;
}

}  // namespace dnbridge::daemon
