#include "adapters/sim/bus/pcap_writer.hpp"

#include <cerrno>
#include <utility>

namespace dnbridge::sim {

namespace {

// Classic pcap, microsecond timestamps. The magic is written in the file's own
// byte order (little-endian here, chosen so files are identical on any host).
constexpr std::uint32_t kPcapMagic = 0xA1B2C3D4;
constexpr std::uint16_t kVersionMajor = 2;
constexpr std::uint16_t kVersionMinor = 4;
constexpr std::size_t kFileHeaderSize = 24;
constexpr std::size_t kRecordHeaderSize = 16;

template <std::size_t N>
void put_le(std::array<std::uint8_t, N>& out, std::size_t at, std::uint32_t v, std::size_t width) {
  for (std::size_t i = 0; i < width; ++i) out[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

std::system_error open_error(int errno_value, const std::string& what, const std::string& path) {
  return std::system_error(errno_value != 0 ? errno_value : EIO, std::generic_category(),
                           "pcap capture: cannot " + what + " '" + path + "'");
}

}  // namespace

PcapWriter::PcapWriter(const std::string& path, TimePoint start,
                       std::chrono::nanoseconds start_since_epoch)
    : path_(path), start_(start), epoch_(start_since_epoch) {
  errno = 0;
  file_.reset(std::fopen(path.c_str(), "wb"));
  if (!file_) throw open_error(errno, "create", path);

  std::array<std::uint8_t, kFileHeaderSize> h{};
  put_le(h, 0, kPcapMagic, 4);
  put_le(h, 4, kVersionMajor, 2);
  put_le(h, 6, kVersionMinor, 2);
  put_le(h, 8, 0, 4);                     // thiszone: timestamps are UTC
  put_le(h, 12, 0, 4);                    // sigfigs
  put_le(h, 16, kSocketcanFrameSize, 4);  // snaplen: every record is whole
  put_le(h, 20, kLinktypeCanSocketcan, 4);
  errno = 0;
  if (std::fwrite(h.data(), 1, h.size(), file_.get()) != h.size() ||
      std::fflush(file_.get()) != 0) {
    const int e = errno;
    file_.reset();
    throw open_error(e, "write the header of", path);
  }
}

PcapWriter::~PcapWriter() = default;

PcapWriter::PcapWriter(PcapWriter&& other) noexcept
    : path_(std::move(other.path_)),
      file_(std::move(other.file_)),
      start_(other.start_),
      epoch_(other.epoch_),
      frames_written_(other.frames_written_),
      write_errors_(other.write_errors_),
      error_(other.error_) {}

PcapWriter& PcapWriter::operator=(PcapWriter&& other) noexcept {
  if (this != &other) {
    file_ = std::move(other.file_);  // closes ours first
    path_ = std::move(other.path_);
    start_ = other.start_;
    epoch_ = other.epoch_;
    frames_written_ = other.frames_written_;
    write_errors_ = other.write_errors_;
    error_ = other.error_;
  }
  return *this;
}

void PcapWriter::fail(int errno_value) noexcept {
  ++write_errors_;
  if (!error_)
    error_ = std::error_code(errno_value != 0 ? errno_value : EIO, std::generic_category());
}

std::array<std::uint8_t, kSocketcanFrameSize> PcapWriter::encode(
    const can::CanFrame& frame) noexcept {
  std::array<std::uint8_t, kSocketcanFrameSize> b{};
  // can_id in network byte order; bits 31..29 (EFF, RTR, ERR) stay clear:
  // DeviceNet uses standard data frames only.
  const std::uint32_t id = frame.id & can::kMaxStandardId;
  b[0] = static_cast<std::uint8_t>(id >> 24);
  b[1] = static_cast<std::uint8_t>(id >> 16);
  b[2] = static_cast<std::uint8_t>(id >> 8);
  b[3] = static_cast<std::uint8_t>(id);
  const std::uint8_t len =
      frame.len <= can::kMaxDataLength ? frame.len : std::uint8_t{can::kMaxDataLength};
  b[4] = len;
  // b[5..7]: padding and reserved, zero. Bytes past the DLC stay zero.
  for (std::size_t i = 0; i < len; ++i) b[8 + i] = frame.data[i];
  return b;
}

bool PcapWriter::write(const can::CanFrame& frame, TimePoint at) noexcept {
  if (!file_) {
    fail(EBADF);
    return false;
  }
  std::chrono::nanoseconds t =
      epoch_ + std::chrono::duration_cast<std::chrono::nanoseconds>(at - start_);
  if (t < std::chrono::nanoseconds::zero()) t = std::chrono::nanoseconds::zero();
  const auto usec = std::chrono::duration_cast<std::chrono::microseconds>(t).count();

  std::array<std::uint8_t, kRecordHeaderSize + kSocketcanFrameSize> r{};
  // ts_sec is 32 bits in classic pcap: good until 2106.
  put_le(r, 0, static_cast<std::uint32_t>(usec / 1000000), 4);
  put_le(r, 4, static_cast<std::uint32_t>(usec % 1000000), 4);
  put_le(r, 8, kSocketcanFrameSize, 4);   // captured length
  put_le(r, 12, kSocketcanFrameSize, 4);  // original length
  const auto body = encode(frame);
  for (std::size_t i = 0; i < body.size(); ++i) r[kRecordHeaderSize + i] = body[i];

  errno = 0;
  if (std::fwrite(r.data(), 1, r.size(), file_.get()) != r.size()) {
    fail(errno);
    return false;
  }
  ++frames_written_;
  return true;
}

bool PcapWriter::flush() noexcept {
  if (!file_) return false;
  errno = 0;
  if (std::fflush(file_.get()) != 0) {
    fail(errno);
    return false;
  }
  return true;
}

bool PcapWriter::close() noexcept {
  if (!file_) return write_errors_ == 0;
  errno = 0;
  const int e1 = std::fflush(file_.get()) != 0 ? errno : 0;
  // fclose reports, among others, errors of the final write-back.
  errno = 0;
  const int rc = std::fclose(file_.release());
  const int e2 = rc != 0 ? (errno != 0 ? errno : EIO) : 0;
  if (e1 != 0) fail(e1);
  if (e2 != 0) fail(e2);
  return write_errors_ == 0;
}

BusCapture::BusCapture(VirtualBus& bus, PcapWriter writer) : bus_(bus), writer_(std::move(writer)) {
  bus_.set_tap([this](const WireFrame& f) { writer_.write(f.frame, f.end); });
}

BusCapture::~BusCapture() {
  if (tapped_) bus_.set_tap({});
}

bool BusCapture::close() noexcept {
  if (tapped_) {
    bus_.set_tap({});
    tapped_ = false;
  }
  return writer_.close();
}

}  // namespace dnbridge::sim
