#include "bridge/cip/service.hpp"

namespace dnbridge::cip {

std::string_view to_string(Service service) noexcept {
  switch (service) {
    case Service::kGetAttributesAll:
      return "Get_Attributes_All";
    case Service::kSetAttributesAll:
      return "Set_Attributes_All";
    case Service::kReset:
      return "Reset";
    case Service::kCreate:
      return "Create";
    case Service::kDelete:
      return "Delete";
    case Service::kApplyAttributes:
      return "Apply_Attributes";
    case Service::kGetAttributeSingle:
      return "Get_Attribute_Single";
    case Service::kSetAttributeSingle:
      return "Set_Attribute_Single";
    case Service::kErrorResponse:
      return "Error_Response";
    case Service::kAllocateMasterSlave:
      return "Allocate_Master/Slave_Connection_Set";
    case Service::kReleaseMasterSlave:
      return "Release_Master/Slave_Connection_Set";
  }
  return {};
}

}  // namespace dnbridge::cip
