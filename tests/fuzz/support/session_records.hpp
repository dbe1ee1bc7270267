#pragma once
// The input format of the two session targets (scanner, cdn127_slave): a
// sequence of records, each an event at a time, and the fixed set-up both
// the targets and the seed recorder (record_sessions.cpp) use.
//
// Record:
//   [op:4 | len:4]        op below; len 0..15, data bytes that follow (at most 8
//                         are a frame's payload)
//   [step u16le]          time since the previous record, in units of 100 us
//   [can id u16le]        frame ops only (bits over 11 are kept: invalid ids too)
//   [data: len bytes]
// A record cut off by the end of the input ends the session.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "adapters/sim/cdn127/cdn127_device.hpp"
#include "adapters/sim/world/sim_rack.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/scan_list.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"
#include "bridge/rack/pump_rack.hpp"

namespace dnbridge::fuzz {

enum class Op : std::uint8_t {
  kFrame = 0,             // 0..7 and 15: a received frame
  kTimer = 8,             // time passes, nothing else
  kSetOutputs = 9,        // scanner: set_outputs(node data[0] % n, data[1..])
  kSetIdle = 10,          // scanner: set_idle(node data[0] % n, data[1] & 1)
  kRequestExplicit = 11,  // scanner: request_explicit(node data[0] % n, request in data[1..])
  kStop = 12,             // scanner: stop(); slave: power cycle
  kScanBus = 13,          // scanner: scan_bus()
  // scanner: node data[0] % n out of the scan list when in it (remove_node),
  // back in when not (add_node; data[1] bit 0: its poll period and EPR
  // doubled, a node configured again)
  kToggleNode = 14,
};

inline constexpr Duration kStepUnit = microseconds(100);
inline constexpr std::size_t kMaxStepUnits = 0xFFFF;
// Sessions start here rather than at the clock's epoch, as a running system would.
inline constexpr TimePoint kSessionStart = TimePoint{} + seconds(1000);

struct Record {
  Op op = Op::kFrame;
  Duration step{};
  can::CanFrame frame;  // for kFrame: the frame; otherwise len/data are the op's data
};

// Reads the next record; nullopt at the end (or a record cut off).
inline std::optional<Record> next_record(ByteReader& in) noexcept {
  const std::uint8_t head = in.u8();
  const std::uint16_t step = in.u16le();
  if (!in.ok()) return std::nullopt;
  Record r;
  const unsigned op = head >> 4;
  r.op = op >= 8 && op <= 14 ? static_cast<Op>(op) : Op::kFrame;
  r.step = kStepUnit * step;
  if (r.op == Op::kFrame) r.frame.id = in.u16le();
  const std::size_t len = head & 0x0FU;
  Bytes data = in.bytes(len);
  if (!in.ok()) return std::nullopt;
  r.frame.len = static_cast<std::uint8_t>(len < can::kMaxDataLength ? len : can::kMaxDataLength);
  for (std::size_t i = 0; i < r.frame.len; ++i) r.frame.data[i] = data[i];
  return r;
}

// Appends a record; a step over the largest one is split into timer records.
inline void append_record(std::vector<std::uint8_t>& out, Op op, Duration step, std::uint32_t id,
                          Bytes data) {
  auto units = static_cast<std::size_t>(step / kStepUnit);
  while (units > kMaxStepUnits) {
    out.push_back(static_cast<std::uint8_t>(static_cast<unsigned>(Op::kTimer) << 4));
    out.push_back(0xFF);
    out.push_back(0xFF);
    units -= kMaxStepUnits;
  }
  out.push_back(static_cast<std::uint8_t>((static_cast<unsigned>(op) << 4) | (data.size() & 0x0FU)));
  out.push_back(static_cast<std::uint8_t>(units & 0xFFU));
  out.push_back(static_cast<std::uint8_t>(units >> 8));
  if (op == Op::kFrame) {
    out.push_back(static_cast<std::uint8_t>(id & 0xFFU));
    out.push_back(static_cast<std::uint8_t>((id >> 8) & 0xFFU));
  }
  out.insert(out.end(), data.begin(), data.end());
}

// The scanner target's scan list: master MAC 0, a CDN127 with its factory
// configuration at MAC 1 and one set to the CDN118 preset at MAC 2, with the
// integration tests' timings.
inline rack::PumpConfig fuzz_pump(unsigned mac, profiles::cdn127::ConfigurationPreset preset) {
  rack::PumpConfig p;
  p.node.mac = devicenet::MacId::from(mac).value();
  p.node.name = "pump";
  p.node.poll_period = milliseconds(100);
  p.node.expected_packet_rate = milliseconds(500);
  p.io = profiles::cdn127::preset(preset);
  return p;
}

inline std::vector<rack::PumpConfig> fuzz_pumps() {
  return {fuzz_pump(1, profiles::cdn127::ConfigurationPreset::kCdn127),
          fuzz_pump(2, profiles::cdn127::ConfigurationPreset::kCdn118)};
}

inline devicenet::ScannerConfig fuzz_scanner_config() {
  devicenet::ScannerConfig port;
  port.master_mac = devicenet::MacId::from(0).value();
  port.vendor_id = 59;
  port.serial_number = 0xDB000001;
  return rack::PumpRack::scanner_config(port, fuzz_pumps());
}

// The slave target's device: a CDN127 at MAC 1 as it leaves the factory.
inline sim::SlaveOptions fuzz_slave_options() {
  return sim::default_slave_options(devicenet::MacId::from(1).value());
}

}  // namespace dnbridge::fuzz
