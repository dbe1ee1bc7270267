#include "bridge/profiles/cdn127/node_profile.hpp"

#include "bridge/cip/epath.hpp"

namespace dnbridge::profiles::cdn127 {
namespace {

devicenet::AttributeSetting configuration_setting(std::uint8_t attribute, std::uint8_t value,
                                                  const char* name) {
  devicenet::AttributeSetting s;
  s.class_id = class_id::kConfiguration;
  s.instance_id = 1;
  s.attribute = attribute;
  s.value = {value};
  s.name = name;
  return s;
}

// Assembly instance `instance`, attribute 3 (data), as a packed 8-bit EPATH.
std::vector<std::uint8_t> assembly_path(std::uint8_t instance) {
  cip::EPath path;
  path.class_id = class_id::kAssembly;
  path.instance_id = instance;
  path.attribute = 3;
  return cip::encoded(path);
}

}  // namespace

Result<devicenet::NodeProfile> make_node_profile(const IoConfiguration& config,
                                                 const SafeStateConfig& safe) {
  auto format = poll_format(config);
  if (!format) return format.error();

  devicenet::NodeProfile p;
  p.identity = {kVendorId, kProductType, kProductCode};
  // Mode first: it decides how the counts that follow are laid out, and the
  // device may check the combination.
  p.settings.push_back(
      configuration_setting(configuration_attr::kMode, config.mode, "Configuration.Mode"));
  p.settings.push_back(configuration_setting(configuration_attr::kNumDigitalInput,
                                             config.num_digital_inputs,
                                             "Configuration.NumDigitalInput"));
  p.settings.push_back(configuration_setting(configuration_attr::kNumDigitalOutput,
                                             config.num_digital_outputs,
                                             "Configuration.NumDigitalOutput"));
  p.settings.push_back(configuration_setting(configuration_attr::kNumAnalogInput,
                                             config.num_analog_inputs,
                                             "Configuration.NumAnalogInput"));
  p.settings.push_back(configuration_setting(configuration_attr::kNumAnalogOutput,
                                             config.num_analog_outputs,
                                             "Configuration.NumAnalogOutput"));
  p.settings.push_back(configuration_setting(configuration_attr::kNoNcMask, config.no_nc_mask,
                                             "Configuration.NoNcMask"));
  // The safe state after the configuration, which decides which outputs exist.
  for (auto& s : safe_state_settings(safe.values, safe.source, config))
    p.settings.push_back(std::move(s));
  p.produced_path = assembly_path(kDefaultProducedAssembly);
  p.consumed_path = assembly_path(kDefaultConsumedAssembly);
  p.produced_size = format->response.size;
  p.consumed_size = format->request.size;
  p.format_description = describe(*format);
  // "Number Produced/Consumed ... Access to this attribute is not dependent
  // on the Poll connection being created" (manual, Configuration object).
  p.has_size_fallback = true;
  p.size_fallback = {.class_id = class_id::kConfiguration,
                     .instance_id = 1,
                     .produced_attribute = configuration_attr::kNumberProduced,
                     .consumed_attribute = configuration_attr::kNumberConsumed,
                     .one_byte = true,
                     .object_name = "Configuration"};
  return p;
}

}  // namespace dnbridge::profiles::cdn127
