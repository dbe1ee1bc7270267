#include "adapters/sim/bus/pcap_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <type_traits>

#include "support/bytes.hpp"

namespace dnbridge::sim {
namespace {

using test::ByteVec;
using test::frame;

constexpr TimePoint at(Duration d) { return TimePoint(d); }

static_assert(!std::is_copy_constructible_v<PcapWriter> && !std::is_copy_assignable_v<PcapWriter>);
static_assert(std::is_nothrow_move_constructible_v<PcapWriter> &&
              std::is_nothrow_move_assignable_v<PcapWriter>);
static_assert(!std::is_copy_constructible_v<BusCapture> &&
              !std::is_move_constructible_v<BusCapture>);

// The 24-byte classic pcap header every capture starts with, little-endian.
const ByteVec kFileHeader = {
    0xD4, 0xC3, 0xB2, 0xA1,  // magic: microsecond timestamps, little-endian file
    0x02, 0x00, 0x04, 0x00,  // version 2.4
    0x00, 0x00, 0x00, 0x00,  // thiszone: UTC
    0x00, 0x00, 0x00, 0x00,  // sigfigs
    0x10, 0x00, 0x00, 0x00,  // snaplen 16: one SocketCAN frame
    0xE3, 0x00, 0x00, 0x00,  // network 227: LINKTYPE_CAN_SOCKETCAN
};

class PcapWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() / ("dnbridge_pcap_" + std::string(info->name()) +
                                                      "_" + std::to_string(::getpid()) + ".pcap");
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  ByteVec contents() const {
    std::ifstream in(path_, std::ios::binary);
    return ByteVec(std::istreambuf_iterator<char>(in), {});
  }
  // Timestamp bytes (ts_sec, ts_usec) of record i.
  ByteVec stamp(std::size_t i) const {
    const ByteVec r = record(i);
    return r.size() < 8 ? r : ByteVec(r.begin(), r.begin() + 8);
  }
  ByteVec record(std::size_t i) const {
    const ByteVec all = contents();
    const std::size_t from = kFileHeader.size() + i * 32;
    if (all.size() < from + 32) return {};
    return ByteVec(all.begin() + static_cast<std::ptrdiff_t>(from),
                   all.begin() + static_cast<std::ptrdiff_t>(from + 32));
  }

  std::filesystem::path path_;
};

TEST_F(PcapWriterTest, HeaderAndOneRecordByteForByte) {
  const TimePoint start = at(seconds(1));
  {
    PcapWriter w(path_.string(), start);
    EXPECT_EQ(contents(), kFileHeader);  // written and flushed at once
    // A master explicit request to MAC 1: Get_Attribute_Single Identity 1/1.
    EXPECT_TRUE(
        w.write(frame(0x40C, {0x00, 0x0E, 0x01, 0x01, 0x01}), start + microseconds(2'000'548)));
    EXPECT_EQ(w.frames_written(), 1u);
    EXPECT_TRUE(w.close());
    EXPECT_FALSE(w.is_open());
  }
  ByteVec expected = kFileHeader;
  const ByteVec rec = {
      0x02, 0x00, 0x00, 0x00,  // ts_sec 2
      0x24, 0x02, 0x00, 0x00,  // ts_usec 548
      0x10, 0x00, 0x00, 0x00,  // captured length 16
      0x10, 0x00, 0x00, 0x00,  // original length 16
      0x00, 0x00, 0x04, 0x0C,  // can_id 0x40C, big-endian, no EFF/RTR/ERR flag
      0x05,                    // DLC
      0x00, 0x00, 0x00,        // padding, reserved
      0x00, 0x0E, 0x01, 0x01, 0x01, 0x00, 0x00, 0x00,  // data, zero past the DLC
  };
  expected.insert(expected.end(), rec.begin(), rec.end());
  EXPECT_EQ(contents(), expected) << test::hex(Bytes(contents().data(), contents().size()));
}

TEST_F(PcapWriterTest, EncodesEveryLengthAndTheHighestIdentifier) {
  const auto empty = PcapWriter::encode(frame(0x7EF, {}));
  EXPECT_EQ(ByteVec(empty.begin(), empty.end()),
            (ByteVec{0x00, 0x00, 0x07, 0xEF, 0x00, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
  const auto full = PcapWriter::encode(frame(0x3C1, {1, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(ByteVec(full.begin(), full.end()),
            (ByteVec{0x00, 0x00, 0x03, 0xC1, 0x08, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8}));
  // Bits above the 11-bit identifier never reach the file as CAN flags.
  can::CanFrame odd = frame(0x123, {9});
  odd.id |= 0xE000'0000;
  const auto masked = PcapWriter::encode(odd);
  EXPECT_EQ(ByteVec(masked.begin(), masked.begin() + 5), (ByteVec{0x00, 0x00, 0x01, 0x23, 0x01}));
}

TEST_F(PcapWriterTest, TimestampsCountFromTheStartPlusItsEpoch) {
  const TimePoint start = at(seconds(50));
  {
    // The start is 2023-11-14 22:13:20.250 UTC.
    PcapWriter w(path_.string(), start, seconds(1'700'000'000) + milliseconds(250));
    EXPECT_TRUE(w.write(frame(0x100, {}), start + milliseconds(1500)));
    EXPECT_TRUE(
        w.write(frame(0x100, {}), start - seconds(10)));  // before the start: still after 1970
    EXPECT_TRUE(w.close());
  }
  // 1700000001.750000 = 0x6553F101 s, 750000 = 0x000B71B0 us
  EXPECT_EQ(stamp(0), (ByteVec{0x01, 0xF1, 0x53, 0x65, 0xB0, 0x71, 0x0B, 0x00}));
  // 1699999990.250000 = 0x6553F0F6 s, 250000 = 0x0003D090 us
  EXPECT_EQ(stamp(1), (ByteVec{0xF6, 0xF0, 0x53, 0x65, 0x90, 0xD0, 0x03, 0x00}));
}

TEST_F(PcapWriterTest, FrameBeforeTheEpochIsStampedAtTheEpoch) {
  const TimePoint start = at(seconds(5));
  {
    PcapWriter w(path_.string(), start);
    EXPECT_TRUE(w.write(frame(0x100, {}), start - microseconds(1)));
    EXPECT_TRUE(w.close());
  }
  EXPECT_EQ(stamp(0), ByteVec(8, 0x00));
}

TEST_F(PcapWriterTest, OpenFailureThrowsNamingTheFile) {
  const std::string bad = (path_.parent_path() / "no-such-directory" / "x.pcap").string();
  try {
    PcapWriter w(bad, TimePoint{});
    FAIL() << "no exception";
  } catch (const std::system_error& e) {
    EXPECT_EQ(e.code(), std::errc::no_such_file_or_directory);
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

TEST_F(PcapWriterTest, HeaderWriteFailureThrows) {
  // /dev/full accepts the open and refuses every write with ENOSPC.
  ASSERT_TRUE(std::filesystem::exists("/dev/full"));
  try {
    PcapWriter w("/dev/full", TimePoint{});
    FAIL() << "no exception";
  } catch (const std::system_error& e) {
    EXPECT_EQ(e.code(), std::errc::no_space_on_device);
    EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
  }
}

TEST_F(PcapWriterTest, WriteErrorsAreCountedAndReported) {
  PcapWriter w(path_.string(), TimePoint{});
  ASSERT_TRUE(w.close());
  EXPECT_FALSE(w.write(frame(0x100, {}), TimePoint{}));
  EXPECT_FALSE(w.write(frame(0x100, {}), TimePoint{}));
  EXPECT_EQ(w.write_errors(), 2u);
  EXPECT_EQ(w.frames_written(), 0u);
  EXPECT_EQ(w.error(), std::errc::bad_file_descriptor);
  EXPECT_FALSE(w.close());
  EXPECT_FALSE(w.flush());
}

TEST_F(PcapWriterTest, MoveHandsOverTheFile) {
  PcapWriter first(path_.string(), TimePoint{});
  PcapWriter second(std::move(first));
  EXPECT_FALSE(first.is_open());  // NOLINT(bugprone-use-after-move): checked on purpose
  EXPECT_FALSE(first.write(frame(0x100, {}), TimePoint{}));
  EXPECT_TRUE(second.write(frame(0x101, {7}), TimePoint{} + seconds(1)));

  const auto other = path_.string() + ".other";
  PcapWriter third(other, TimePoint{});
  third = std::move(second);  // closes `other`, takes over path_
  EXPECT_EQ(third.path(), path_.string());
  EXPECT_TRUE(third.write(frame(0x102, {8}), TimePoint{} + seconds(2)));
  EXPECT_EQ(third.frames_written(), 2u);
  EXPECT_TRUE(third.close());
  EXPECT_EQ(contents().size(), kFileHeader.size() + 2 * 32);
  EXPECT_EQ(record(1)[19], 0x02);  // can_id low byte of the second frame
  std::error_code ignored;
  EXPECT_EQ(std::filesystem::file_size(other), kFileHeader.size());
  std::filesystem::remove(other, ignored);
}

// A node that only listens.
class Listener final : public BusPort {
 public:
  void on_frame(const can::CanFrame&, TimePoint) override { ++count; }
  std::size_t count = 0;
};

TEST_F(PcapWriterTest, BusCaptureRecordsEveryFrameAtItsEndOfFrame) {
  VirtualBus bus({.bitrate = can::kBitrate500k});
  Listener a, b;
  const NodeHandle ha = bus.attach(a);
  const TimePoint start = at(seconds(1));
  const can::CanFrame check = frame(0x407, {0x00, 0x3B, 0x00, 0x01, 0x00, 0x00, 0xDB});
  {
    BusCapture capture(bus, PcapWriter(path_.string(), start));
    // Alone on the bus, unacknowledged: captured all the same.
    bus.send(ha, check, start);
    bus.advance(start + milliseconds(1));
    const NodeHandle hb = bus.attach(b);
    bus.send(hb, frame(0x40B, {0x00, 0xCB, 0x00}), start + milliseconds(2));
    bus.advance(start + milliseconds(3));
    EXPECT_EQ(capture.frames(), 2u);
    EXPECT_TRUE(capture.close());
    // Closed: the bus runs on without its tap.
    bus.send(ha, check, start + milliseconds(4));
    bus.advance(start + milliseconds(5));
    EXPECT_EQ(capture.frames(), 2u);
  }
  bus.send(ha, check, start + milliseconds(6));  // capture gone: nothing refers to it
  bus.advance(start + milliseconds(7));
  EXPECT_EQ(bus.stats().transmitted, 4u);

  ASSERT_EQ(contents().size(), kFileHeader.size() + 2 * 32);
  const auto usec = [](Duration d) {
    return static_cast<std::uint32_t>(std::chrono::duration_cast<microseconds>(d).count());
  };
  const std::uint32_t end0 = usec(can::frame_duration(check, can::kBitrate500k));
  const ByteVec r0 = record(0);
  EXPECT_EQ(ByteVec(r0.begin() + 4, r0.begin() + 8),
            (ByteVec{static_cast<std::uint8_t>(end0), static_cast<std::uint8_t>(end0 >> 8), 0, 0}));
  EXPECT_EQ(ByteVec(r0.begin() + 16, r0.end()), (ByteVec{0, 0, 0x04, 0x07, 7, 0, 0, 0, 0x00, 0x3B,
                                                         0x00, 0x01, 0x00, 0x00, 0xDB, 0x00}));
  const ByteVec r1 = record(1);
  EXPECT_EQ(r1[19], 0x0B);
  const std::uint32_t end1 =
      2000 + usec(can::frame_duration(frame(0x40B, {0, 0xCB, 0}), can::kBitrate500k));
  EXPECT_EQ(ByteVec(r1.begin() + 4, r1.begin() + 8),
            (ByteVec{static_cast<std::uint8_t>(end1), static_cast<std::uint8_t>(end1 >> 8), 0, 0}));
}

}  // namespace
}  // namespace dnbridge::sim
