#pragma once
// The DDS domain of this test process. Every participant of the process, and
// every dnbctl it runs (they inherit CYCLONEDDS_URI), is pinned to loopback
// with a discovery tag of this process's own (test_domain.cpp sets it before
// any test), so parallel test processes never hear each other.
#include <cstdint>

namespace dnbridge::dnbctl::testing {

std::uint32_t test_domain();

}  // namespace dnbridge::dnbctl::testing
