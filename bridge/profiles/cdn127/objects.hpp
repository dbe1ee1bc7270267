#pragma once
// The CDN127 object map: classes, instances, attributes and fixed identity
// values, as the CDN127 DeviceNet Specifications (rev 1.6) list them.
#include <cstdint>

#include "bridge/cip/objects.hpp"

namespace dnbridge::profiles::cdn127 {

// Identity object values for a CDN127.
inline constexpr std::uint16_t kVendorId = 59;       // D.I.P. Inc.
inline constexpr std::uint16_t kProductType = 27;    // Dry Pump Device
inline constexpr std::uint16_t kProductCode = 1888;  // CDN127

// Classes: the ODVA common ones (cip::class_id, bridge/cip/objects.hpp) and
// the two the CDN127 manual adds.
namespace class_id {
using namespace cip::class_id;
inline constexpr std::uint16_t kDeviceSupervisor = 0x32;
inline constexpr std::uint16_t kConfiguration = 0x40;
}  // namespace class_id

// The attributes of the objects every device has are cip's.
namespace identity_attr = cip::identity_attr;
namespace devicenet_attr = cip::devicenet_attr;
namespace connection_instance = cip::connection_instance;
namespace connection_attr = cip::connection_attr;
namespace class_attr = cip::class_attr;

// The attributes of the CDN127's I/O points, as its manual numbers them.
namespace dip_attr {
inline constexpr std::uint8_t kValue = 3, kStatus = 4;
}
namespace dop_attr {
inline constexpr std::uint8_t kValue = 3, kStatus = 4, kFaultAction = 5, kFaultValue = 6,
                              kIdleAction = 7, kIdleValue = 8;
}
namespace aip_attr {
inline constexpr std::uint8_t kValue = 3, kStatus = 4, kRange = 7, kDataType = 8;
}
namespace aop_attr {
inline constexpr std::uint8_t kValue = 3, kRange = 7, kDataType = 8, kFaultState = 9,
                              kIdleState = 10, kFaultValue = 11, kIdleValue = 12;
}
namespace supervisor_attr {
inline constexpr std::uint8_t kManufacturerType = 3, kSemiRevisionLevel = 4, kManufacturerName = 5,
                              kManufacturerModel = 6, kSoftwareRevision = 7, kHardwareRevision = 8,
                              kDeviceStatus = 11, kExceptionStatus = 12, kExceptionDetail = 13,
                              kWarningDetail = 14, kAlarmEnable = 15, kWarningEnable = 16;
}
namespace configuration_attr {
inline constexpr std::uint8_t kMode = 1, kNumDigitalInput = 2, kNumDigitalOutput = 3,
                              kNumAnalogInput = 4, kNumAnalogOutput = 5, kNoNcMask = 10,
                              kNumberProduced = 16, kNumberConsumed = 17;
}

// Argument of the Configuration object's Reset service.
enum class ConfigurationPreset : std::uint8_t { kCdn127 = 0, kCdn118 = 1 };

}  // namespace dnbridge::profiles::cdn127
