#pragma once
// The ODVA common objects a DeviceNet master addresses in every device, by
// name: the Identity object (class 0x01), the DeviceNet object (0x03) and the
// Connection object (0x05) with its two predefined Group 2 instances. A
// profile's own objects are its profile's (profiles/cdn127/objects.hpp).
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

namespace identity {
inline constexpr std::uint16_t kClass = 0x01;
inline constexpr AttributeRef kVendorId{kClass, 1, 1, "Identity.VendorID"};
inline constexpr AttributeRef kProductType{kClass, 1, 2, "Identity.ProductType"};
inline constexpr AttributeRef kProductCode{kClass, 1, 3, "Identity.ProductCode"};
inline constexpr AttributeRef kRevision{kClass, 1, 4, "Identity.Revision"};
inline constexpr AttributeRef kStatus{kClass, 1, 5, "Identity.Status"};
inline constexpr AttributeRef kSerialNumber{kClass, 1, 6, "Identity.SerialNumber"};
inline constexpr AttributeRef kProductName{kClass, 1, 7, "Identity.ProductName"};
inline constexpr AttributeRef kState{kClass, 1, 8, "Identity.State"};
}  // namespace identity

namespace devicenet_object {
inline constexpr std::uint16_t kClass = 0x03;
// {allocation choice BYTE, master MAC USINT (255: none)}
inline constexpr AttributeRef kAllocationInformation{kClass, 1, 5,
                                                     "DeviceNet.AllocationInformation"};
}  // namespace devicenet_object

namespace connection {
inline constexpr std::uint16_t kClass = 0x05;
inline constexpr std::uint16_t kExplicitInstance = 1;  // explicit messaging
inline constexpr std::uint16_t kPollInstance = 2;      // polled I/O

inline constexpr AttributeRef kExplicitExpectedPacketRate{
    kClass, kExplicitInstance, 9, "Connection 1 (explicit).ExpectedPacketRate"};
inline constexpr AttributeRef kPollProducedSize{kClass, kPollInstance, 7,
                                                "Connection 2 (poll).ProducedConnectionSize"};
inline constexpr AttributeRef kPollConsumedSize{kClass, kPollInstance, 8,
                                                "Connection 2 (poll).ConsumedConnectionSize"};
inline constexpr AttributeRef kPollExpectedPacketRate{kClass, kPollInstance, 9,
                                                      "Connection 2 (poll).ExpectedPacketRate"};
// The CDN127 manual labels attribute 16 "Production Path" too; it is the
// consumed path (the ODVA Connection object's attribute 16).
inline constexpr AttributeRef kPollProducedPath{kClass, kPollInstance, 14,
                                                "Connection 2 (poll).ProducedConnectionPath"};
inline constexpr AttributeRef kPollConsumedPath{kClass, kPollInstance, 16,
                                                "Connection 2 (poll).ConsumedConnectionPath"};
}  // namespace connection

}  // namespace dnbridge::cip
