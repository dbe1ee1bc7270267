#include "bridge/cip/general_status.hpp"

namespace dnbridge::cip {

std::string_view to_string(GeneralStatus status) noexcept {
  switch (status) {
    case GeneralStatus::kSuccess:
      return "success";
    case GeneralStatus::kConnectionFailure:
      return "connection failure";
    case GeneralStatus::kResourceUnavailable:
      return "resource unavailable";
    case GeneralStatus::kInvalidParameterValue:
      return "invalid parameter value";
    case GeneralStatus::kPathSegmentError:
      return "path segment error";
    case GeneralStatus::kPathDestinationUnknown:
      return "path destination unknown";
    case GeneralStatus::kPartialTransfer:
      return "partial transfer";
    case GeneralStatus::kConnectionLost:
      return "connection lost";
    case GeneralStatus::kServiceNotSupported:
      return "service not supported";
    case GeneralStatus::kInvalidAttributeValue:
      return "invalid attribute value";
    case GeneralStatus::kAttributeListError:
      return "attribute list error";
    case GeneralStatus::kAlreadyInRequestedMode:
      return "already in requested mode/state";
    case GeneralStatus::kObjectStateConflict:
      return "object state conflict";
    case GeneralStatus::kObjectAlreadyExists:
      return "object already exists";
    case GeneralStatus::kAttributeNotSettable:
      return "attribute not settable";
    case GeneralStatus::kPrivilegeViolation:
      return "privilege violation";
    case GeneralStatus::kDeviceStateConflict:
      return "device state conflict";
    case GeneralStatus::kReplyDataTooLarge:
      return "reply data too large";
    case GeneralStatus::kFragmentationOfPrimitiveValue:
      return "fragmentation of a primitive value";
    case GeneralStatus::kNotEnoughData:
      return "not enough data";
    case GeneralStatus::kAttributeNotSupported:
      return "attribute not supported";
    case GeneralStatus::kTooMuchData:
      return "too much data";
    case GeneralStatus::kObjectDoesNotExist:
      return "object does not exist";
    case GeneralStatus::kFragmentationSequenceNotInProgress:
      return "fragmentation sequence not in progress";
    case GeneralStatus::kNoStoredAttributeData:
      return "no stored attribute data";
    case GeneralStatus::kStoreOperationFailure:
      return "store operation failure";
    case GeneralStatus::kRequestTooLarge:
      return "routing failure, request too large";
    case GeneralStatus::kResponseTooLarge:
      return "routing failure, response too large";
    case GeneralStatus::kMissingAttributeListEntry:
      return "missing attribute list entry";
    case GeneralStatus::kInvalidAttributeValueList:
      return "invalid attribute value list";
    case GeneralStatus::kEmbeddedServiceError:
      return "embedded service error";
    case GeneralStatus::kVendorSpecific:
      return "vendor specific error";
    case GeneralStatus::kInvalidParameter:
      return "invalid parameter";
    case GeneralStatus::kWriteOnceAlreadyWritten:
      return "write-once value already written";
    case GeneralStatus::kInvalidReplyReceived:
      return "invalid reply received";
    case GeneralStatus::kBufferOverflow:
      return "buffer overflow";
    case GeneralStatus::kInvalidMessageFormat:
      return "invalid message format";
    case GeneralStatus::kKeyFailureInPath:
      return "key failure in path";
    case GeneralStatus::kPathSizeInvalid:
      return "path size invalid";
    case GeneralStatus::kUnexpectedAttributeInList:
      return "unexpected attribute in list";
    case GeneralStatus::kInvalidMemberId:
      return "invalid member ID";
    case GeneralStatus::kMemberNotSettable:
      return "member not settable";
    case GeneralStatus::kGroup2OnlyServerFailure:
      return "Group 2 only server general failure";
    case GeneralStatus::kAttributeNotGettable:
      return "attribute not gettable";
  }
  return {};
}

bool is_known(std::uint8_t code) noexcept {
  return !to_string(static_cast<GeneralStatus>(code)).empty();
}

}  // namespace dnbridge::cip
