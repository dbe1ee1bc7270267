#pragma once
// The ODVA objects, by number and by name: the class codes of the common
// objects (class_id, with their names in one table, kClasses), the
// attribute numbers of the objects every DeviceNet device has (Identity,
// DeviceNet, Connection with its predefined Group 2 instances), and the
// attributes the master addresses by name (AttributeRef).
//
// One scheme for every object: `<object>_attr::` holds its attribute
// numbers, `<object>_instance::` its instance numbers where it has more than
// one, and `<object>::` (`devicenet_object::` for the DeviceNet object, whose
// name is the namespace of the master) its class code and the AttributeRefs. What a profile defines
// itself (its vendor classes, the attribute numbers its manual gives for its I/O points) is its
// profile's (profiles/cdn127/objects.hpp).
#include <array>
#include <cstdint>
#include <string_view>

namespace dnbridge::cip {

// One attribute of one object instance, as a request addresses it.
struct AttributeRef {
  std::uint16_t class_id = 0;
  std::uint16_t instance_id = 0;
  std::uint8_t attribute = 0;
  std::string_view name;  // "Identity.VendorID": for reasons and logs

  friend constexpr bool operator==(const AttributeRef& a, const AttributeRef& b) noexcept {
    return a.class_id == b.class_id && a.instance_id == b.instance_id && a.attribute == b.attribute;
  }
};

namespace class_id {
inline constexpr std::uint16_t kIdentity = 0x01;
inline constexpr std::uint16_t kMessageRouter = 0x02;
inline constexpr std::uint16_t kDeviceNet = 0x03;
inline constexpr std::uint16_t kAssembly = 0x04;
inline constexpr std::uint16_t kConnection = 0x05;
inline constexpr std::uint16_t kDiscreteInputPoint = 0x08;
inline constexpr std::uint16_t kDiscreteOutputPoint = 0x09;
inline constexpr std::uint16_t kAnalogInputPoint = 0x0A;
inline constexpr std::uint16_t kAnalogOutputPoint = 0x0B;
inline constexpr std::uint16_t kParameter = 0x0F;
inline constexpr std::uint16_t kAcknowledgeHandler = 0x2B;
}  // namespace class_id

// A class and its name as the CIP specification gives it.
struct CipClass {
  std::uint16_t id = 0;
  std::string_view name;
};

// Every class of class_id, in its order.
inline constexpr std::array<CipClass, 11> kClasses{{
    {class_id::kIdentity, "Identity"},
    {class_id::kMessageRouter, "Message Router"},
    {class_id::kDeviceNet, "DeviceNet"},
    {class_id::kAssembly, "Assembly"},
    {class_id::kConnection, "Connection"},
    {class_id::kDiscreteInputPoint, "Discrete Input Point"},
    {class_id::kDiscreteOutputPoint, "Discrete Output Point"},
    {class_id::kAnalogInputPoint, "Analog Input Point"},
    {class_id::kAnalogOutputPoint, "Analog Output Point"},
    {class_id::kParameter, "Parameter"},
    {class_id::kAcknowledgeHandler, "Acknowledge Handler"},
}};

// "Identity", "Discrete Output Point", ...; empty for a class not in kClasses.
constexpr std::string_view class_name(std::uint16_t class_id) noexcept {
  for (const CipClass& c : kClasses) {
    if (c.id == class_id) return c.name;
  }
  return {};
}

// Attribute numbers of the objects every device has.
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
inline constexpr std::uint16_t kExplicit = 1, kPoll = 2, kBitStrobe = 3;
inline constexpr std::uint16_t kChangeOfState = 4;  // change of state or cyclic
}  // namespace connection_instance
namespace connection_attr {
inline constexpr std::uint8_t kState = 1, kInstanceType = 2, kTransportClassTrigger = 3,
                              kProducedConnectionId = 4, kConsumedConnectionId = 5,
                              kInitialCommCharacteristics = 6, kProducedSize = 7, kConsumedSize = 8,
                              kExpectedPacketRate = 9, kWatchdogTimeoutAction = 12,
                              kProducedPathLength = 13, kProducedPath = 14,
                              kConsumedPathLength = 15, kConsumedPath = 16, kInhibitTime = 17;
}
namespace acknowledge_handler_attr {
inline constexpr std::uint8_t kAcknowledgeTimer = 1, kRetryLimit = 2, kProducingInstance = 3;
}
// Class attributes (instance 0) common to the objects.
namespace class_attr {
inline constexpr std::uint8_t kRevision = 1, kMaxInstance = 2, kMaxClassId = 6,
                              kMaxInstanceAttribute = 7;
}
// The Assembly object's instance attributes (its class attributes are
// class_attr's 1 and 2): the member list and the data (cip/assembly.hpp).
namespace assembly_attr {
inline constexpr std::uint8_t kMemberCount = 1, kMemberList = 2, kData = 3;
}

namespace identity {
inline constexpr std::uint16_t kClass = class_id::kIdentity;
inline constexpr AttributeRef kVendorId{kClass, 1, identity_attr::kVendor, "Identity.VendorID"};
inline constexpr AttributeRef kProductType{kClass, 1, identity_attr::kProductType,
                                           "Identity.ProductType"};
inline constexpr AttributeRef kProductCode{kClass, 1, identity_attr::kProductCode,
                                           "Identity.ProductCode"};
inline constexpr AttributeRef kRevision{kClass, 1, identity_attr::kRevision, "Identity.Revision"};
inline constexpr AttributeRef kStatus{kClass, 1, identity_attr::kStatus, "Identity.Status"};
inline constexpr AttributeRef kSerialNumber{kClass, 1, identity_attr::kSerialNumber,
                                            "Identity.SerialNumber"};
inline constexpr AttributeRef kProductName{kClass, 1, identity_attr::kProductName,
                                           "Identity.ProductName"};
inline constexpr AttributeRef kState{kClass, 1, identity_attr::kState, "Identity.State"};
}  // namespace identity

namespace devicenet_object {
inline constexpr std::uint16_t kClass = class_id::kDeviceNet;
// {allocation choice BYTE, master MAC USINT (255: none)}
inline constexpr AttributeRef kAllocationInformation{kClass, 1, devicenet_attr::kAllocationInfo,
                                                     "DeviceNet.AllocationInformation"};
}  // namespace devicenet_object

namespace connection {
inline constexpr std::uint16_t kClass = class_id::kConnection;

inline constexpr AttributeRef kExplicitExpectedPacketRate{
    kClass, connection_instance::kExplicit, connection_attr::kExpectedPacketRate,
    "Connection 1 (explicit).ExpectedPacketRate"};
inline constexpr AttributeRef kPollProducedSize{kClass, connection_instance::kPoll,
                                                connection_attr::kProducedSize,
                                                "Connection 2 (poll).ProducedConnectionSize"};
inline constexpr AttributeRef kPollConsumedSize{kClass, connection_instance::kPoll,
                                                connection_attr::kConsumedSize,
                                                "Connection 2 (poll).ConsumedConnectionSize"};
inline constexpr AttributeRef kPollExpectedPacketRate{kClass, connection_instance::kPoll,
                                                      connection_attr::kExpectedPacketRate,
                                                      "Connection 2 (poll).ExpectedPacketRate"};
// The CDN127 manual labels attribute 16 "Production Path" too; it is the
// consumed path (the ODVA Connection object's attribute 16).
inline constexpr AttributeRef kPollProducedPath{kClass, connection_instance::kPoll,
                                                connection_attr::kProducedPath,
                                                "Connection 2 (poll).ProducedConnectionPath"};
inline constexpr AttributeRef kPollConsumedPath{kClass, connection_instance::kPoll,
                                                connection_attr::kConsumedPath,
                                                "Connection 2 (poll).ConsumedConnectionPath"};

// Instance 4: change of state or cyclic, as allocated.
inline constexpr AttributeRef kCosProducedSize{
    kClass, connection_instance::kChangeOfState, connection_attr::kProducedSize,
    "Connection 4 (change of state).ProducedConnectionSize"};
inline constexpr AttributeRef kCosExpectedPacketRate{
    kClass, connection_instance::kChangeOfState, connection_attr::kExpectedPacketRate,
    "Connection 4 (change of state).ExpectedPacketRate"};
inline constexpr AttributeRef kCosProducedPath{
    kClass, connection_instance::kChangeOfState, connection_attr::kProducedPath,
    "Connection 4 (change of state).ProducedConnectionPath"};
inline constexpr AttributeRef kCosInhibitTime{kClass, connection_instance::kChangeOfState,
                                              connection_attr::kInhibitTime,
                                              "Connection 4 (change of state).InhibitTime"};

// Instance 3: bit-strobe.
inline constexpr AttributeRef kStrobeProducedSize{
    kClass, connection_instance::kBitStrobe, connection_attr::kProducedSize,
    "Connection 3 (bit-strobe).ProducedConnectionSize"};
inline constexpr AttributeRef kStrobeExpectedPacketRate{
    kClass, connection_instance::kBitStrobe, connection_attr::kExpectedPacketRate,
    "Connection 3 (bit-strobe).ExpectedPacketRate"};
inline constexpr AttributeRef kStrobeProducedPath{
    kClass, connection_instance::kBitStrobe, connection_attr::kProducedPath,
    "Connection 3 (bit-strobe).ProducedConnectionPath"};
}  // namespace connection

// The Acknowledge Handler (instance 1): how long the device waits for an
// acknowledgment of a change-of-state or cyclic message before it sends it
// again (UINT ms), and how often it does (USINT).
namespace acknowledge_handler {
inline constexpr std::uint16_t kClass = class_id::kAcknowledgeHandler;
inline constexpr AttributeRef kAckTimer{kClass, 1, acknowledge_handler_attr::kAcknowledgeTimer,
                                        "Acknowledge Handler.AcknowledgeTimer"};
inline constexpr AttributeRef kRetryLimit{kClass, 1, acknowledge_handler_attr::kRetryLimit,
                                          "Acknowledge Handler.RetryLimit"};
inline constexpr AttributeRef kProducingInstance{kClass, 1,
                                                 acknowledge_handler_attr::kProducingInstance,
                                                 "Acknowledge Handler.ProducingConnectionInstance"};
}  // namespace acknowledge_handler

}  // namespace dnbridge::cip
