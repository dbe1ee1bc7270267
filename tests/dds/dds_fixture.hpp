#pragma once
// What every DDS test shares: a participant on this process's own domain
// (loopback only: see loopback_environment.cpp), a rack name unique to the
// test so that keys never collide, and bounded waits for events.
#include <gtest/gtest.h>

#include <string>

#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"

namespace dnbridge::dds::testing {

// 100 + pid % 100: parallel test processes do not hear each other.
dds_domainid_t test_domain();

// Long enough never to be reached when things work; bounds a failure.
inline constexpr Duration kEventTimeout = seconds(5);

// Waits until `entity` (a read condition, or an entity whose status mask is
// set) triggers; false on timeout.
inline bool wait_for(const Participant& participant, const Entity& entity,
                     Duration timeout = kEventTimeout) {
  WaitSet waitset(participant);
  waitset.attach(entity, 1);
  auto triggered = waitset.wait(timeout);
  return triggered.ok() && !triggered->empty();
}

class DdsTest : public ::testing::Test {
 protected:
  DdsTest()
      : rack_(::testing::UnitTest::GetInstance()->current_test_info()->name()),
        participant_(test_domain(), rack_) {}

  std::string rack_;
  Participant participant_;
};

}  // namespace dnbridge::dds::testing
