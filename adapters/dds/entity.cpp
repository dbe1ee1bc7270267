#include "adapters/dds/entity.hpp"

#include <string>

namespace dnbridge::dds {
namespace {

class DdsCategory final : public std::error_category {
 public:
  const char* name() const noexcept override { return "dds"; }
  std::string message(int code) const override { return dds_strretcode(code); }
};

std::string describe(std::string_view attempted, dds_return_t code) {
  std::string text(attempted);
  text += ": ";
  text += dds_strretcode(code);
  text += " (";
  text += std::to_string(code);
  text += ")";
  if (code == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY) {
    text += ": DDS Security, the permissions of this participant's identity do not allow it";
  }
  return text;
}

}  // namespace

Error::Error(std::string_view attempted, dds_return_t code)
    : std::runtime_error(describe(attempted, code)), code_(code) {}

Error::Error(std::string_view attempted, dds_return_t code, std::string_view reason)
    : std::runtime_error(std::string(attempted) + ": " + std::string(reason)), code_(code) {}

const std::error_category& dds_category() noexcept {
  static const DdsCategory category;
  return category;
}

dds_entity_t check(dds_entity_t result, std::string_view attempted) {
  if (result < 0) throw Error(attempted, result);
  return result;
}

Result<dds_instance_handle_t> Entity::instance_handle() const noexcept {
  dds_instance_handle_t ih = 0;
  const dds_return_t rc = dds_get_instance_handle(handle_, &ih);
  if (rc < 0) return make_error_code(rc);
  return ih;
}

Result<std::string> Entity::entity_name() const {
  dds_qos_t* qos = dds_create_qos();
  const dds_return_t rc = dds_get_qos(handle_, qos);
  std::string name;
  char* text = nullptr;
  if (rc >= 0 && dds_qget_entity_name(qos, &text) && text != nullptr) {
    name = text;
    dds_free(text);
  }
  dds_delete_qos(qos);
  if (rc < 0) return make_error_code(rc);
  return name;
}

}  // namespace dnbridge::dds
