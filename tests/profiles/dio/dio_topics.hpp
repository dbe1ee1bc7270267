#pragma once
// The DDS side of the test-only profile "dio": its IDL types on their
// topics, its samples filled from its view and its command read, and the
// profile registered beside the bridge's own (dio_profiles), as a product
// profile is in bridge_profiles().
#include <span>
#include <string_view>

#include "adapters/daemon/profile_topics.hpp"
#include "dio.h"
#include "profiles/dio/dio_rack.hpp"

namespace dnbridge::dds {

template <>
struct TopicTraits<dnbridge_test_DioState> {
  static constexpr const char* kName = "dnbridge_test/DioState";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_test_DioState_desc;
};
template <>
struct TopicTraits<dnbridge_test_DioCommand> {
  static constexpr const char* kName = "dnbridge_test/DioCommand";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_test_DioCommand_desc;
};

}  // namespace dnbridge::dds

namespace dnbridge::test::dio {

void fill_dio_state(dnbridge_test_DioState& out, std::string_view rack, std::string_view port,
                    const DioView& v);
void fill_dio_status(dnbridge_NodeStatus& out, std::string_view rack, std::string_view port,
                     const DioView& v, const port::NodeStatusView& status);
rack::NodeCommand command_of(const dnbridge_test_DioCommand& c);

// The bridge's profiles and "dio".
std::span<const daemon::ProfileTopics> dio_profiles();

}  // namespace dnbridge::test::dio
