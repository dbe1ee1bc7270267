// The simulated CDN127 on the wire, frame by frame with a fake clock
// (cdn127_slave_fixture.hpp): the Connection object's attributes, poll I/O
// with the CDN127 and CDN118 presets, idle and oversize polls, and the
// watchdogs with the fault actions they apply.
#include <gtest/gtest.h>

#include <cstdint>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "sim/cdn127/cdn127_slave_fixture.hpp"

namespace dnbridge::sim {
namespace {

// ---------------------------------------------------------------------------
// Connection object

TEST_F(Cdn127SlaveTest, ExpectedPacketRateRoundsUpToTheTimerResolution) {
  boot();
  allocate();
  // Set EPR 3594 ms -> the device keeps and returns 3600 (bridge/PROTOCOL.md §7).
  EXPECT_EQ(single(kRequestId, {kMaster, 0x10, 0x05, 0x02, 0x09, 0x0A, 0x0E}),
            (ByteVec{kMaster, 0x90, 0x10, 0x0E}));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kEstablished);
  EXPECT_EQ(get(0x05, 0x02, 0x09), (ByteVec{0x8E, 0x10, 0x0E}));
  EXPECT_EQ(get(0x05, 0x02, 0x01), (ByteVec{0x8E, 0x03}));
  // explicit connection: default 2500 ms
  EXPECT_EQ(get(0x05, 0x01, 0x09), (ByteVec{0x8E, 0xC4, 0x09}));
}

TEST_F(Cdn127SlaveTest, ConnectionAttributes) {
  boot();
  allocate();
  // explicit instance 1
  EXPECT_EQ(get(0x05, 0x01, 0x01), (ByteVec{0x8E, 0x03}));
  EXPECT_EQ(get(0x05, 0x01, 0x02), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x05, 0x01, 0x03), (ByteVec{0x8E, 0x83}));
  EXPECT_EQ(get(0x05, 0x01, 0x04), (ByteVec{0x8E, 0x1B, 0x04}));  // 0x41B
  EXPECT_EQ(get(0x05, 0x01, 0x05), (ByteVec{0x8E, 0x1C, 0x04}));  // 0x41C
  EXPECT_EQ(get(0x05, 0x01, 0x06), (ByteVec{0x8E, 0x21}));
  EXPECT_EQ(get(0x05, 0x01, 0x07), (ByteVec{0x8E, 0x18, 0x00}));
  EXPECT_EQ(get(0x05, 0x01, 0x08), (ByteVec{0x8E, 0x18, 0x00}));
  EXPECT_EQ(get(0x05, 0x01, 0x0C), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x05, 0x01, 0x0D), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x05, 0x01, 0x0E), (ByteVec{0x8E}));
  EXPECT_EQ(get(0x05, 0x01, 0x11), (ByteVec{0x8E, 0x00, 0x00}));
  EXPECT_EQ(get(0x05, 0x01, 0x0A), error(0x14));
  // explicit watchdog action is fixed (Get only in the manual)
  EXPECT_EQ(set(0x05, 0x01, 0x0C, {0x03}), error(0x0E));
  // poll instance 2, defaults: assemblies 103/104 with the CDN127 preset
  EXPECT_EQ(get(0x05, 0x02, 0x02), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x05, 0x02, 0x03), (ByteVec{0x8E, 0x82}));
  EXPECT_EQ(get(0x05, 0x02, 0x04), (ByteVec{0x8E, 0xC3, 0x03}));  // 0x3C3
  EXPECT_EQ(get(0x05, 0x02, 0x05), (ByteVec{0x8E, 0x1D, 0x04}));  // 0x41D
  EXPECT_EQ(get(0x05, 0x02, 0x06), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x05, 0x02, 0x07), (ByteVec{0x8E, 0x06, 0x00}));  // DSUP DIN AIN AIN
  EXPECT_EQ(get(0x05, 0x02, 0x08), (ByteVec{0x8E, 0x04, 0x00}));  // DOUT PAD AOUT
  EXPECT_EQ(get(0x05, 0x02, 0x0C), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x05, 0x02, 0x0D), (ByteVec{0x8E, 0x06}));
  EXPECT_EQ(get(0x05, 0x02, 0x0E), (ByteVec{0x8E, 0x20, 0x04, 0x24, 0x67, 0x30, 0x03}));
  EXPECT_EQ(get(0x05, 0x02, 0x0F), (ByteVec{0x8E, 0x06}));
  EXPECT_EQ(get(0x05, 0x02, 0x10), (ByteVec{0x8E, 0x20, 0x04, 0x24, 0x68, 0x30, 0x03}));
  // watchdog action 0..3 on the poll connection
  EXPECT_EQ(set(0x05, 0x02, 0x0C, {0x04}), error(0x09));
  EXPECT_EQ(set(0x05, 0x02, 0x0C, {0x02}), (ByteVec{0x90}));
  // produced path: assembly 2 (exception byte, input byte)
  EXPECT_EQ(set(0x05, 0x02, 0x0E, {0x20, 0x04, 0x24, 0x02, 0x30, 0x03}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x05, 0x02, 0x07), (ByteVec{0x8E, 0x02, 0x00}));
  // a consumed assembly named as produced, and a path to another class
  EXPECT_EQ(set(0x05, 0x02, 0x0E, {0x20, 0x04, 0x24, 0x05, 0x30, 0x03}), error(0x09));
  EXPECT_EQ(set(0x05, 0x02, 0x10, {0x20, 0x01, 0x24, 0x01, 0x30, 0x03}), error(0x09));
  // class attribute 1 only
  EXPECT_EQ(get(0x05, 0x00, 0x01), (ByteVec{0x8E, 0x01, 0x00}));
  EXPECT_EQ(get(0x05, 0x00, 0x02), error(0x14));
  // paths are fixed once the connection is established
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x0E, {0x20, 0x04, 0x24, 0x01, 0x30, 0x03}), error(0x0C));
}

// A firmware without the poll connection's Produced/Consumed Size answers
// them as attributes it has not (0x14), on Get and Set alike; the
// Configuration object's Number Produced/Consumed still answer, in USINT.
TEST_F(Cdn127SlaveTest, FirmwareWithoutConnectionSizesRefusesThemWithAttributeNotSupported) {
  SlaveOptions o = default_options();
  o.unsupported_attributes = {{0x05, 7}, {0x05, 8}};
  create(o);
  boot();
  allocate();
  EXPECT_EQ(get(0x05, 0x02, 0x07), error(0x14));
  EXPECT_EQ(get(0x05, 0x02, 0x08), error(0x14));
  EXPECT_EQ(get(0x05, 0x01, 0x07), error(0x14));
  EXPECT_EQ(set(0x05, 0x02, 0x07, {0x06, 0x00}), error(0x14));  // not 0x0E: it has none
  EXPECT_EQ(get(0x05, 0x02, 0x0D), (ByteVec{0x8E, 0x06}));      // the rest as before
  EXPECT_EQ(get(0x40, 0x01, 16), (ByteVec{0x8E, 0x06}));        // DSUP DIN AIN AIN
  EXPECT_EQ(get(0x40, 0x01, 17), (ByteVec{0x8E, 0x04}));        // DOUT PAD AOUT
}

// A firmware that has an attribute Get only although the manual lists it
// Get/Set: its Get answers, its Set is refused with 0x0E and changes nothing.
TEST_F(Cdn127SlaveTest, FirmwareWithAReadOnlyAttributeAnswersItsGetAndRefusesItsSet) {
  SlaveOptions o = default_options();
  o.read_only_attributes = {{0x0B, 9}};
  create(o);
  boot();
  allocate();
  EXPECT_EQ(get(0x0B, 0x01, 9), (ByteVec{0x8E, 0x00}));  // AOP Fault State: hold
  EXPECT_EQ(set(0x0B, 0x01, 9, {0x03}), error(0x0E));
  EXPECT_EQ(slave_->device().e2().aop.fault_state, 0);
  EXPECT_EQ(set(0x0B, 0x01, 10, {0x03}), (ByteVec{0x90}));  // the others as before
  EXPECT_EQ(slave_->device().e2().aop.idle_state, 3);
}

TEST_F(Cdn127SlaveTest, PollConnectionDoesNotExistBeforeAllocation) {
  boot();
  allocate(0x01);
  EXPECT_EQ(get(0x05, 0x02, 0x01), error(0x16));
  EXPECT_EQ(get(0x05, 0x03, 0x01), error(0x16));
}

// ---------------------------------------------------------------------------
// Poll I/O

TEST_F(Cdn127SlaveTest, PollRoundTripWithTheCdn127Preset) {
  boot();
  ASSERT_TRUE(slave_->pump().set_analog_input(0, 0x0123));
  ASSERT_TRUE(slave_->pump().set_analog_input(1, 0x0FFF));
  establish_poll(1000);  // watchdog 4 s: outlives the spin-up wait below
  // request: [DOUT: pump on | N2 ballast][PAD][AOUT 0x0800 LE]
  const ByteVec r = poll({0x05, 0x00, 0x00, 0x08});
  // response: [DSUP: expanded mode, no alarm][DIN: no warning, N2 ok, no alarm,
  // interlock ok; not running yet][AIN1 LE][AIN2 LE]
  EXPECT_EQ(r, (ByteVec{0x80, 0x1E, 0x23, 0x01, 0xFF, 0x0F}));
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0800);
  EXPECT_EQ(slave_->pump().last_cause(), OutputCause::kPoll);
  // The pump runs after its spin-up delay.
  advance(seconds(3));
  EXPECT_EQ(poll({0x05, 0x00, 0x00, 0x08}), (ByteVec{0x80, 0x1F, 0x23, 0x01, 0xFF, 0x0F}));
  // DOP/AOP/AIP/DIP read the same state
  EXPECT_EQ(get(0x09, 0x01, 0x03), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x09, 0x02, 0x03), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x0B, 0x01, 0x03), (ByteVec{0x8E, 0x00, 0x08}));
  EXPECT_EQ(get(0x0A, 0x01, 0x03), (ByteVec{0x8E, 0x23, 0x01}));
  EXPECT_EQ(get(0x08, 0x01, 0x03), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x04, 0x68, 0x03), (ByteVec{0x8E, 0x05, 0x00, 0x00, 0x08}));  // assembly 104
  EXPECT_EQ(get(0x32, 0x01, 0x0B), (ByteVec{0x8E, 0x04}));                    // Executing
  EXPECT_EQ(slave_->counters().polls_applied, 2u);
}

TEST_F(Cdn127SlaveTest, PollRoundTripWithTheCdn118Preset) {
  boot();
  allocate();
  // Configuration Reset to the CDN118 preset while the poll connection configures.
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), (ByteVec{0x85}));
  EXPECT_EQ(get(0x40, 0x01, 0x01), (ByteVec{0x8E, 0x81}));
  EXPECT_EQ(get(0x05, 0x02, 0x07), (ByteVec{0x8E, 0x02, 0x00}));
  EXPECT_EQ(get(0x05, 0x02, 0x08), (ByteVec{0x8E, 0x03, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  // request: [DOUT: pump on][AOUT 4095 LE] (NoEvenByte: no pad)
  // response: [DSUP][DIN]
  EXPECT_EQ(poll({0x01, 0xFF, 0x0F}), (ByteVec{0x80, 0x1E}));
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_FALSE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 4095);
}

TEST_F(Cdn127SlaveTest, NoPollUpdateIsObservableWithAnInstantPump) {
  SlaveOptions o = default_options();
  o.pump.spin_up = Duration::zero();
  o.pump.spin_down = Duration::zero();
  create(o);
  boot();
  establish_poll();
  // CDN127 preset (Mode 0x86, NoPollUpdate): inputs sampled before the outputs change.
  EXPECT_EQ(poll({0x01, 0x00, 0x00, 0x00})[1] & 0x01, 0);
  EXPECT_EQ(poll({0x01, 0x00, 0x00, 0x00})[1] & 0x01, 1);

  // CDN118 preset (Mode 0x81): I/O updated during poll processing.
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4C, 0x03, 0x01, 0x03}), (ByteVec{kMaster, 0xCC}));
  allocate();
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), (ByteVec{0x85}));
  ASSERT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(poll({0x00, 0x00, 0x00})[1] & 0x01, 0);
  EXPECT_EQ(poll({0x01, 0x00, 0x00})[1] & 0x01, 1);
}

TEST_F(Cdn127SlaveTest, ShortPollIsIdleAndAppliesIdleActions) {
  boot();
  allocate();
  // DOP 2 (ballast) holds on idle; AOP idle state 3 with idle value 1000.
  EXPECT_EQ(set(0x09, 0x02, 0x07, {0x01}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x0A, {0x03}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x0C, {0xE8, 0x03}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  poll({0x05, 0x00, 0x00, 0x08});
  ASSERT_TRUE(slave_->outputs().pump_on);

  // 0-byte poll: idle. Still answered.
  const ByteVec r = poll({});
  EXPECT_EQ(r.size(), 6u);
  EXPECT_FALSE(slave_->outputs().pump_on);       // idle value 0
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);  // held
  EXPECT_EQ(slave_->outputs().analog_out_raw, 1000);
  EXPECT_TRUE(slave_->pump().last_change_was_idle());
  EXPECT_EQ(slave_->counters().polls_idle, 1u);
  EXPECT_EQ(get(0x32, 0x01, 0x0B), (ByteVec{0x8E, 0x02}));  // Device Supervisor: Idle
  // A short but non-empty poll is idle too.
  poll({0x01});
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->counters().polls_idle, 2u);
}

TEST_F(Cdn127SlaveTest, ZeroConsumedSizeHasNoIdleCondition) {
  boot();
  allocate();
  // No digital or analog outputs: consumed size 0.
  EXPECT_EQ(set(0x40, 0x01, 0x03, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x40, 0x01, 0x05, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x40, 0x01, 0x11), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(poll({}).size(), 6u);
  EXPECT_EQ(slave_->counters().polls_idle, 0u);
  EXPECT_EQ(slave_->counters().polls_applied, 1u);
}

TEST_F(Cdn127SlaveTest, OversizePollIsIgnored) {
  boot();
  establish_poll();
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->counters().polls_oversize, 1u);
  EXPECT_FALSE(slave_->outputs().pump_on);
}

TEST_F(Cdn127SlaveTest, PollIgnoredUntilEstablished) {
  boot();
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00}).empty());
  allocate();
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->counters().polls_ignored, 2u);
}

TEST_F(Cdn127SlaveTest, AnalogOutputOverRangeInAPollKeepsTheOutputs) {
  boot();
  establish_poll();
  const ByteVec r = poll({0x01, 0x00, 0x00, 0x10});  // 4096
  EXPECT_EQ(r.size(), 6u);
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->counters().polls_invalid, 1u);
}

// ---------------------------------------------------------------------------
// Watchdogs and fault actions

TEST_F(Cdn127SlaveTest, SilencePastFourTimesEprAppliesFaultActionsAndReleases) {
  boot();
  allocate();
  // DOP 2 fault value on; AOP fault state 2 (high limit).
  EXPECT_EQ(set(0x09, 0x02, 0x06, {0x01}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x02}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));  // 100 ms
  poll({0x01, 0x00, 0x00, 0x01});
  ASSERT_TRUE(slave_->outputs().pump_on);

  advance(milliseconds(399));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kEstablished);
  EXPECT_TRUE(slave_->outputs().pump_on);
  advance(milliseconds(1));
  // Watchdog action 0: timed out; outputs to their fault states.
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_FALSE(slave_->outputs().pump_on);       // fault value 0
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);  // fault value 1
  EXPECT_EQ(slave_->outputs().analog_out_raw, 4095);
  EXPECT_TRUE(slave_->pump().last_change_was_fault());
  // Polls are not consumed by a timed-out connection.
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00}).empty());
  // The explicit connection still stands: the master still owns the slave.
  EXPECT_EQ(slave_->owner(), kMaster);
  // With the explicit connection silent for 4 x 2500 ms nothing is left
  // established: the slave releases everything.
  advance(seconds(10));
  EXPECT_EQ(slave_->explicit_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->owner(), 255);
  EXPECT_EQ(slave_->device().watchdog_timeouts(), 2u);
  allocate();  // the master must allocate again
}

TEST_F(Cdn127SlaveTest, PollsAndRequestsKeepTheWatchdogsFed) {
  boot();
  establish_poll(100);
  for (int i = 0; i < 100; ++i) {
    advance(milliseconds(300));
    poll({0x01, 0x00, 0x00, 0x00});
    if (i % 10 == 0) get(0x01, 0x01, 0x01);  // every 3 s: within 4 x 2500 ms
  }
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kEstablished);
  EXPECT_EQ(slave_->explicit_state(), ConnectionState::kEstablished);
  EXPECT_TRUE(slave_->outputs().pump_on);
}

TEST_F(Cdn127SlaveTest, AutoDeleteWithoutExplicitReleasesAtOnce) {
  boot();
  establish_poll(100);
  EXPECT_EQ(set(0x05, 0x02, 0x0C, {0x01}), (ByteVec{0x90}));  // auto delete
  // The explicit connection's EPR can be raised; here it is left to expire first.
  for (int i = 0; i < 40; ++i) {  // 10 s of polls, no explicit requests
    advance(milliseconds(250));
    poll({0x01, 0x00, 0x00, 0x00});
  }
  EXPECT_EQ(slave_->explicit_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->owner(), kMaster);  // the poll connection still runs
  advance(milliseconds(400));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->owner(), 255);
  EXPECT_FALSE(slave_->outputs().pump_on);
}

TEST_F(Cdn127SlaveTest, ConnectionResetRevivesATimedOutPoll) {
  boot();
  establish_poll(100);
  advance(milliseconds(400));
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_EQ(request({0x05, 0x05, 0x02}), (ByteVec{0x85}));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kEstablished);
  EXPECT_EQ(poll({0x01, 0x00, 0x00, 0x00}).size(), 6u);
}

TEST_F(Cdn127SlaveTest, FaultHoldKeepsOutputs) {
  boot();
  allocate();
  EXPECT_EQ(set(0x09, 0x01, 0x05, {0x01}), (ByteVec{0x90}));  // hold
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x00}), (ByteVec{0x90}));  // hold
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  poll({0x01, 0x00, 0x34, 0x02});
  advance(milliseconds(400));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0234);
}

}  // namespace
}  // namespace dnbridge::sim
