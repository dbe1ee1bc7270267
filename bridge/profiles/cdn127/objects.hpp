#pragma once
// The CDN127 object map: classes, instances, attributes and fixed identity
// values, as the CDN127 DeviceNet Specifications (rev 1.6) list them.
#include <cstdint>

namespace dnbridge::profiles::cdn127 {

// Identity object values for a CDN127.
inline constexpr std::uint16_t kVendorId = 59;       // D.I.P. Inc.
inline constexpr std::uint16_t kProductType = 27;    // Dry Pump Device
inline constexpr std::uint16_t kProductCode = 1888;  // CDN127

namespace class_id {
inline constexpr std::uint8_t kIdentity = 0x01;
inline constexpr std::uint8_t kRouter = 0x02;
inline constexpr std::uint8_t kDeviceNet = 0x03;
inline constexpr std::uint8_t kAssembly = 0x04;
inline constexpr std::uint8_t kConnection = 0x05;
inline constexpr std::uint8_t kDiscreteInputPoint = 0x08;
inline constexpr std::uint8_t kDiscreteOutputPoint = 0x09;
inline constexpr std::uint8_t kAnalogInputPoint = 0x0A;
inline constexpr std::uint8_t kAnalogOutputPoint = 0x0B;
inline constexpr std::uint8_t kDeviceSupervisor = 0x32;
inline constexpr std::uint8_t kConfiguration = 0x40;
}  // namespace class_id

namespace identity_attr {
inline constexpr std::uint8_t kVendor = 1, kProductType = 2, kProductCode = 3, kRevision = 4,
                              kStatus = 5, kSerialNumber = 6, kProductName = 7, kState = 8;
}
namespace devicenet_attr {
inline constexpr std::uint8_t kMacId = 1, kBaudRate = 2, kBusOffInterrupt = 3, kBusOffCounter = 4,
                              kAllocationInfo = 5, kMacSwitchChanged = 6, kBaudSwitchChanged = 7,
                              kMacSwitchValue = 8, kBaudSwitchValue = 9;
}
namespace connection_instance {
inline constexpr std::uint8_t kExplicit = 1, kPoll = 2;
}
namespace connection_attr {
inline constexpr std::uint8_t kState = 1, kInstanceType = 2, kTransportClassTrigger = 3,
                              kProducedConnectionId = 4, kConsumedConnectionId = 5,
                              kInitialCommCharacteristics = 6, kProducedSize = 7,
                              kConsumedSize = 8, kExpectedPacketRate = 9, kWatchdogTimeoutAction = 12,
                              kProducedPathLength = 13, kProducedPath = 14,
                              kConsumedPathLength = 15, kConsumedPath = 16, kInhibitTime = 17;
}
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
inline constexpr std::uint8_t kManufacturerType = 3, kSemiRevisionLevel = 4,
                              kManufacturerName = 5, kManufacturerModel = 6,
                              kSoftwareRevision = 7, kHardwareRevision = 8, kDeviceStatus = 11,
                              kExceptionStatus = 12, kExceptionDetail = 13, kWarningDetail = 14,
                              kAlarmEnable = 15, kWarningEnable = 16;
}
namespace configuration_attr {
inline constexpr std::uint8_t kMode = 1, kNumDigitalInput = 2, kNumDigitalOutput = 3,
                              kNumAnalogInput = 4, kNumAnalogOutput = 5, kNoNcMask = 10,
                              kNumberProduced = 16, kNumberConsumed = 17;
}
// Class attributes common to the objects.
namespace class_attr {
inline constexpr std::uint8_t kRevision = 1, kMaxInstance = 2, kMaxClassId = 6,
                              kMaxInstanceAttribute = 7;
}

// Argument of the Configuration object's Reset service.
enum class ConfigurationPreset : std::uint8_t { kCdn127 = 0, kCdn118 = 1 };

}  // namespace dnbridge::profiles::cdn127
