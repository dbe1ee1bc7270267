// The master's receive filters pass exactly the DeviceNet traffic it reads.
#include <gtest/gtest.h>

#include "adapters/socketcan/socketcan_backend.hpp"

namespace dnbridge::socketcan {
namespace {

bool passes(std::uint32_t id) {
  for (const auto& f : master_filters()) {
    if ((id & f.mask) == (f.id & f.mask)) return true;
  }
  return false;
}

TEST(MasterFilters, PassWhatTheMasterReads) {
  EXPECT_TRUE(passes(0x3C0 | 5));              // Group 1 msg 15: poll response of MAC 5
  EXPECT_TRUE(passes(0x340 | 5));              // Group 1 msg 13: COS/cyclic of MAC 5
  EXPECT_TRUE(passes(0x380 | 5));              // Group 1 msg 14: bit-strobe response of MAC 5
  EXPECT_TRUE(passes(0x400 | (5 << 3) | 3));   // Group 2 msg 3: explicit response of MAC 5
  EXPECT_TRUE(passes(0x400 | (0 << 3) | 7));   // Group 2 msg 7: duplicate MAC check, MAC 0
  EXPECT_TRUE(passes(0x400 | (63 << 3) | 7));  // ... and of any other MAC
  EXPECT_TRUE(passes(0x7EC));                  // Group 4: Communication Faulted response
  EXPECT_TRUE(passes(0x7EE));                  // Group 4: Offline Ownership response
}

TEST(MasterFilters, KeepOutWhatItDoesNotRead) {
  EXPECT_FALSE(passes(0x300 | 5));             // Group 1 msg 12: multicast poll response
  EXPECT_FALSE(passes(0x400 | (5 << 3)));      // Group 2 msg 0: a bit-strobe command
  EXPECT_FALSE(passes(0x400 | (5 << 3) | 5));  // Group 2 msg 5: another master's poll
  EXPECT_FALSE(passes(0x400 | (5 << 3) | 4));  // Group 2 msg 4: explicit request
  EXPECT_FALSE(passes(0x400 | (5 << 3) | 6));  // Group 2 msg 6: Allocate
  EXPECT_FALSE(passes(0x600 | 5));             // Group 3
}

}  // namespace
}  // namespace dnbridge::socketcan
