#pragma once
// Captures of CAN traffic as classic pcap files that Wireshark and tshark read:
// LINKTYPE_CAN_SOCKETCAN (227), the format of a SocketCAN capture, so the same
// tools work on simulated and real buses. Decode DeviceNet with
//   tshark -r FILE -d 'can.subdissector,devicenet'
// (the DeviceNet dissector has no heuristic; bridge/PROTOCOL.md §11).
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <system_error>

#include "adapters/sim/bus/virtual_bus.hpp"
#include "bridge/can/can_frame.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::sim {

inline constexpr std::uint32_t kLinktypeCanSocketcan = 227;
// Bytes of one frame's record body: can_id (4, big-endian), DLC, 3 reserved, 8 data.
inline constexpr std::size_t kSocketcanFrameSize = 16;

// One pcap file, open from construction to destruction. Move-only: the file
// has one owner. Timestamps have microsecond resolution (classic pcap).
class PcapWriter {
 public:
  // Creates or truncates `path` and writes the file header. `start` is the
  // TimePoint recorded as `start_since_epoch` (Unix time; zero gives times
  // counted from 1970-01-01, i.e. relative times, which keeps test captures
  // byte-for-byte reproducible). Throws std::system_error naming the file when
  // it cannot be opened or the header cannot be written.
  PcapWriter(const std::string& path, TimePoint start,
             std::chrono::nanoseconds start_since_epoch = std::chrono::nanoseconds::zero());
  ~PcapWriter();
  PcapWriter(PcapWriter&& other) noexcept;
  PcapWriter& operator=(PcapWriter&& other) noexcept;
  PcapWriter(const PcapWriter&) = delete;
  PcapWriter& operator=(const PcapWriter&) = delete;

  // Appends one frame received at `at`. A frame stamped before the start of
  // the epoch is stamped at the epoch. Returns false when the write fails; the
  // failure is counted and the first error kept (see error()). A moved-from
  // writer fails every write.
  bool write(const can::CanFrame& frame, TimePoint at) noexcept;
  // Pushes buffered records to the file; false if that failed (counted too).
  bool flush() noexcept;
  // Flushes and closes; false if this or any earlier write failed. Further
  // writes fail. The destructor closes too, silently: call close() to know.
  bool close() noexcept;

  bool is_open() const noexcept { return file_ != nullptr; }
  const std::string& path() const noexcept { return path_; }
  std::uint64_t frames_written() const noexcept { return frames_written_; }
  std::uint64_t write_errors() const noexcept { return write_errors_; }
  // The first error seen, empty if none.
  std::error_code error() const noexcept { return error_; }

  // The 16 bytes a frame occupies in a LINKTYPE_CAN_SOCKETCAN record.
  static std::array<std::uint8_t, kSocketcanFrameSize> encode(const can::CanFrame& frame) noexcept;

 private:
  struct FileCloser {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
  };
  void fail(int errno_value) noexcept;

  std::string path_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  TimePoint start_;
  std::chrono::nanoseconds epoch_;
  std::uint64_t frames_written_ = 0;
  std::uint64_t write_errors_ = 0;
  std::error_code error_;
};

// Records every frame that completes on `bus` (acknowledged or not; see
// WireFrame) into a pcap file, stamped with its end-of-frame time, for as long
// as it lives. It owns the bus's tap: create one at a time per bus, and
// destroy it before the bus. Neither copyable nor movable (the tap refers to it).
class BusCapture {
 public:
  BusCapture(VirtualBus& bus, PcapWriter writer);
  ~BusCapture();
  BusCapture(const BusCapture&) = delete;
  BusCapture& operator=(const BusCapture&) = delete;

  PcapWriter& writer() noexcept { return writer_; }
  std::uint64_t frames() const noexcept { return writer_.frames_written(); }
  // Stops capturing and closes the file; false if any write failed.
  bool close() noexcept;

 private:
  VirtualBus& bus_;
  PcapWriter writer_;
  bool tapped_ = true;
};

}  // namespace dnbridge::sim
