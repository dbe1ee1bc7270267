#include "bridge/common/error.hpp"

namespace dnbridge {
namespace {

class Category final : public std::error_category {
 public:
  const char* name() const noexcept override { return "dnbridge"; }
  std::string message(int ev) const override {
    switch (static_cast<Errc>(ev)) {
      case Errc::kTruncated:
        return "input truncated";
      case Errc::kMalformed:
        return "malformed input";
      case Errc::kOutOfRange:
        return "value out of range";
      case Errc::kBufferTooSmall:
        return "output buffer too small";
      case Errc::kUnsupported:
        return "not supported";
      case Errc::kInvalidIdentifier:
        return "not a DeviceNet CAN identifier";
      case Errc::kBusy:
        return "busy";
      case Errc::kTimeout:
        return "timed out";
      case Errc::kAborted:
        return "aborted";
      case Errc::kNotConnected:
        return "not connected";
      case Errc::kDeviceError:
        return "device returned an error status";
      case Errc::kStopped:
        return "stopped";
    }
    return "unknown dnbridge error";
  }
};

}  // namespace

const std::error_category& dnbridge_category() noexcept {
  static const Category category;
  return category;
}

}  // namespace dnbridge
