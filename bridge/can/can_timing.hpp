#pragma once
// On-wire length of a classic CAN 2.0A data frame, bit stuffing included, and
// the time it occupies the bus. The simulated bus uses this to place deliveries
// where a real bus would (bridge/PROTOCOL.md §10).
#include <cstdint>

#include "bridge/can/can_frame.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::can {

// DeviceNet's three bit rates (bridge/PROTOCOL.md §10; DeviceNet Object attribute 2).
inline constexpr std::uint32_t kBitrate125k = 125000;
inline constexpr std::uint32_t kBitrate250k = 250000;
inline constexpr std::uint32_t kBitrate500k = 500000;

// Bounds for n data bytes, interframe space included (Davis, Burns, Bril,
// Lukkien 2007): 47 + 8n bits unstuffed, at most 55 + 10n with stuffing.
constexpr std::uint32_t unstuffed_frame_bits(std::uint32_t n) noexcept { return 47 + 8 * n; }
constexpr std::uint32_t max_frame_bits(std::uint32_t n) noexcept { return 55 + 10 * n; }

// CRC-15/CAN (polynomial 0x4599, initial value 0) over bytes fed MSB first.
// The frame CRC is over a bit string that is not byte-aligned; this form exists
// to check the engine against the catalogue check value.
std::uint16_t crc15(Bytes bytes) noexcept;

// The CRC sequence of a data frame, computed over SOF, identifier, RTR, IDE,
// r0, DLC and data. A len over 8 is treated as 8.
std::uint16_t frame_crc(const CanFrame& frame) noexcept;

// Stuff bits the transmitter inserts between SOF and the end of the CRC.
std::uint32_t stuff_bits(const CanFrame& frame) noexcept;

// Exact length in bits: SOF..CRC with stuffing, then CRC delimiter, ACK slot,
// ACK delimiter, 7 bits EOF and 3 bits intermission.
std::uint32_t frame_bits(const CanFrame& frame) noexcept;

// frame_bits at `bitrate` bit/s, rounded up to the nanosecond. bitrate 0 gives 0.
Duration frame_duration(const CanFrame& frame, std::uint32_t bitrate) noexcept;

// The time `bits` bit times take at `bitrate`, rounded up to the nanosecond.
Duration bits_duration(std::uint64_t bits, std::uint32_t bitrate) noexcept;

}  // namespace dnbridge::can
