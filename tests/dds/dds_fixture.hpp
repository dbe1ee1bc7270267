#pragma once
// What every DDS test shares: a participant on this process's own domain
// (loopback only: see loopback_environment.cpp), a rack name unique to the
// test so that keys never collide, and bounded waits for events.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

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

// Waits until `writer` (of `participant`) has matched `count` readers;
// false on timeout.
template <class T>
bool until_matched(const Participant& participant, const Writer<T>& writer,
                   std::uint32_t count = 1) {
  if (!writer.set_status_mask(DDS_PUBLICATION_MATCHED_STATUS).ok()) return false;
  const auto deadline = std::chrono::steady_clock::now() + kEventTimeout;
  for (;;) {
    auto m = writer.publication_matched();
    if (m.ok() && m->current_count >= count) return true;
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) return false;
    (void)wait_for(participant, writer, deadline - now);
  }
}

class DdsTest : public ::testing::Test {
 protected:
  DdsTest()
      : rack_(::testing::UnitTest::GetInstance()->current_test_info()->name()),
        participant_(test_domain(), rack_) {}

  std::string rack_;
  Participant participant_;
};

// A sample as it travels (CDR from its encapsulation header on), with the
// type Cyclone serialises its topic with.
struct Serialized {
  std::vector<unsigned char> bytes;
  const ddsi_sertype* type = nullptr;
};

// Takes one sample of `reader` serialized; empty bytes when it holds none.
inline Serialized take_serialized(const Entity& reader) {
  ddsi_serdata* raw = nullptr;
  dds_sample_info_t info{};
  if (dds_takecdr(reader.handle(), &raw, 1, &info, DDS_ANY_STATE) != 1) return {};
  Serialized out{std::vector<unsigned char>(ddsi_serdata_size(raw)), raw->type};
  ddsi_serdata_to_ser(raw, 0, out.bytes.size(), out.bytes.data());
  ddsi_serdata_unref(raw);
  return out;
}

// Writes serialized bytes as they are: what a client in a language whose
// strings may hold a NUL can send, which a C struct cannot.
inline dds_return_t write_serialized(const Entity& writer, Serialized sample) {
  ddsrt_iovec_t iov{};
  iov.iov_base = sample.bytes.data();
  iov.iov_len = static_cast<ddsrt_iov_len_t>(sample.bytes.size());
  ddsi_serdata* raw =
      ddsi_serdata_from_ser_iov(sample.type, SDK_DATA, 1, &iov, sample.bytes.size());
  if (raw == nullptr) return DDS_RETCODE_BAD_PARAMETER;
  return dds_writecdr(writer.handle(), raw);
}

// `sample` with the first `from` in its bytes made a NUL; false if none.
inline bool put_nul(Serialized& sample, std::string_view from) {
  const auto at = std::search(sample.bytes.begin(), sample.bytes.end(), from.begin(), from.end());
  if (at == sample.bytes.end()) return false;
  *at = 0;
  return true;
}

}  // namespace dnbridge::dds::testing
