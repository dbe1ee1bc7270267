#include "bridge/cip/service.hpp"

namespace dnbridge::cip {

std::string_view to_string(Service service) noexcept {
  switch (service) {
    case Service::kReset:
      return "Reset";
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
