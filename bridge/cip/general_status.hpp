#pragma once
// CIP general status codes (bridge/PROTOCOL.md §4), every code named. A device's
// error reply is data, carried as a Status value, never an exception.
#include <cstdint>
#include <string_view>

namespace dnbridge::cip {

enum class GeneralStatus : std::uint8_t {
  kSuccess = 0x00,
  kConnectionFailure = 0x01,
  kResourceUnavailable = 0x02,
  kInvalidParameterValue = 0x03,
  kPathSegmentError = 0x04,
  kPathDestinationUnknown = 0x05,
  kPartialTransfer = 0x06,
  kConnectionLost = 0x07,
  kServiceNotSupported = 0x08,
  kInvalidAttributeValue = 0x09,
  kAttributeListError = 0x0A,
  kAlreadyInRequestedMode = 0x0B,
  kObjectStateConflict = 0x0C,
  kObjectAlreadyExists = 0x0D,
  kAttributeNotSettable = 0x0E,
  kPrivilegeViolation = 0x0F,
  kDeviceStateConflict = 0x10,
  kReplyDataTooLarge = 0x11,
  kFragmentationOfPrimitiveValue = 0x12,
  kNotEnoughData = 0x13,
  kAttributeNotSupported = 0x14,
  kTooMuchData = 0x15,
  kObjectDoesNotExist = 0x16,
  kFragmentationSequenceNotInProgress = 0x17,
  kNoStoredAttributeData = 0x18,
  kStoreOperationFailure = 0x19,
  kRequestTooLarge = 0x1A,   // routing failure, request packet too large
  kResponseTooLarge = 0x1B,  // routing failure, response packet too large
  kMissingAttributeListEntry = 0x1C,
  kInvalidAttributeValueList = 0x1D,
  kEmbeddedServiceError = 0x1E,
  kVendorSpecific = 0x1F,
  kInvalidParameter = 0x20,
  kWriteOnceAlreadyWritten = 0x21,
  kInvalidReplyReceived = 0x22,
  kBufferOverflow = 0x23,
  kInvalidMessageFormat = 0x24,
  kKeyFailureInPath = 0x25,
  kPathSizeInvalid = 0x26,
  kUnexpectedAttributeInList = 0x27,
  kInvalidMemberId = 0x28,
  kMemberNotSettable = 0x29,
  kGroup2OnlyServerFailure = 0x2A,  // small Group 2 only servers, instead of 08/14/0E
  kAttributeNotGettable = 0x2C,
};

// "no additional code" in an error response
inline constexpr std::uint8_t kNoAdditionalCode = 0xFF;

// A human-readable name; "reserved (0xNN)"-style text is left to the caller for
// codes outside the table (returns an empty view for those).
std::string_view to_string(GeneralStatus status) noexcept;

// True for the codes named above.
bool is_known(std::uint8_t code) noexcept;

}  // namespace dnbridge::cip
