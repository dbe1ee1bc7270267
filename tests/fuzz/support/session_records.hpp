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
  out.push_back(
      static_cast<std::uint8_t>((static_cast<unsigned>(op) << 4) | (data.size() & 0x0FU)));
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
// integration tests' timings; and the example valve manifold (deploy/eds) at
// MAC 3, bit-strobed.
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

// The valve manifold's profile as the EDS profile builds it (without its
// settings and member list checks): identity, the status byte (Assembly
// 102) produced on the poll and bit-strobe connections, the coils (Assembly
// 151) consumed.
inline constexpr unsigned kFuzzStrobedMac = 3;
inline devicenet::NodeConfig fuzz_strobed_node() {
  devicenet::NodeConfig n;
  n.mac = devicenet::MacId::from(kFuzzStrobedMac).value();
  n.name = "valves";
  n.poll_period = milliseconds(100);
  n.expected_packet_rate = milliseconds(500);
  n.profile.identity = {65001, 27, 2};
  n.profile.produced_path = {0x20, 0x04, 0x24, 0x66, 0x30, 0x03};
  n.profile.consumed_path = {0x20, 0x04, 0x24, 0x97, 0x30, 0x03};
  n.profile.produced_size = 1;
  n.profile.consumed_size = 2;
  devicenet::InputConnection strobe;
  strobe.kind = devicenet::InputKind::kBitStrobe;
  strobe.produced_path = n.profile.produced_path;
  strobe.produced_size = 1;
  n.profile.input_connection = strobe;
  return n;
}

inline devicenet::ScannerConfig fuzz_scanner_config() {
  devicenet::ScannerConfig port;
  port.master_mac = devicenet::MacId::from(0).value();
  port.vendor_id = 59;
  port.serial_number = 0xDB000001;
  devicenet::ScannerConfig c = rack::PumpRack::scanner_config(port, fuzz_pumps());
  c.nodes.push_back(fuzz_strobed_node());
  return c;
}

// The slave target's device: a CDN127 at MAC 1 as it leaves the factory.
inline sim::SlaveOptions fuzz_slave_options() {
  return sim::default_slave_options(devicenet::MacId::from(1).value());
}

}  // namespace dnbridge::fuzz
