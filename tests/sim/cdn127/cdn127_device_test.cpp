// The simulated CDN127 device (Cdn127Device) without its wire: its clock. A
// produced assembly read through the message router is sampled at the
// request's time.
#include "adapters/sim/cdn127/cdn127_device.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <optional>

#include "adapters/sim/cdn127/cdn127_objects.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::test {
namespace {

constexpr unsigned kMasterMac = 0;

// An explicit Get of a produced assembly samples the pump at the request's
// time, not at the last poll's or timer's: the device is driven by the
// request alone here (the message router, no wire, no timer).
TEST(Cdn127DeviceClock, AProducedAssemblyIsSampledWhenItIsRead) {
  sim::Cdn127Device device(sim::SlaveOptions{});
  const TimePoint t0 = TimePoint{} + seconds(100);
  device.power_up(t0, sim::PowerUpCause::kPowerOn);
  profiles::cdn127::PumpOutputs on;
  on.pump_on = true;
  ASSERT_TRUE(device.set_outputs(on, sim::OutputCause::kExplicit, t0).ok());  // spin-up 3 s
  const auto running_at = [&](TimePoint now) -> std::optional<bool> {
    devicenet::RequestMessage get;
    get.service = 0x0E;
    get.class_id = 0x04;
    get.instance_id = profiles::cdn127::kDefaultProducedAssembly;
    get.attribute = 3;
    std::array<std::uint8_t, devicenet::kMaxExplicitMessage> out{};
    const std::size_t n = sim::execute_request(device, get, kMasterMac, now, MutableBytes(out));
    if (n < 1 || out[0] != 0x8E) return std::nullopt;
    auto layout = profiles::cdn127::produced_assembly_layout(
        profiles::cdn127::kDefaultProducedAssembly, device.configuration());
    if (!layout.ok()) return std::nullopt;
    auto in = profiles::cdn127::decode_poll_response(*layout, device.configuration().no_nc_mask,
                                                     Bytes(out.data() + 1, n - 1));
    if (!in.ok() || !in->pump) return std::nullopt;
    return in->pump->pump_running;
  };
  EXPECT_EQ(running_at(t0 + seconds(1)), false);
  EXPECT_EQ(running_at(t0 + seconds(4)), true);
}

}  // namespace
}  // namespace dnbridge::test
