// The simulated CDN127 on the wire, frame by frame with a fake clock
// (cdn127_slave_fixture.hpp): the Configuration, Device Supervisor and
// DeviceNet objects, the errors for services and attributes the tables do
// not list, the factory output actions (safe and unsafe) and the Identity
// faults.
#include <gtest/gtest.h>

#include <cstdint>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "sim/cdn127/cdn127_slave_fixture.hpp"

namespace dnbridge::sim {
namespace {

// ---------------------------------------------------------------------------
// Configuration object

TEST_F(Cdn127SlaveTest, ConfigurationChangeRefusedWhilePolling) {
  boot();
  allocate();
  // Before the poll connection is established: accepted, sizes follow.
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x01}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x40, 0x01, 0x10), (ByteVec{0x8E, 0x04}));  // DSUP DIN AIN
  EXPECT_EQ(get(0x05, 0x02, 0x07), (ByteVec{0x8E, 0x04, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  // Established: object state conflict, for Set and Reset alike.
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x02}), error(0x0C));
  EXPECT_EQ(set(0x40, 0x01, 0x0A, {0x01}), error(0x0C));
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x00}), error(0x0C));
  EXPECT_EQ(get(0x40, 0x01, 0x04), (ByteVec{0x8E, 0x01}));
  // Out of range values
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4C, 0x03, 0x01, 0x02}), (ByteVec{kMaster, 0xCC}));
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x03}), error(0x09));
  EXPECT_EQ(set(0x40, 0x01, 0x05, {0x02}), error(0x09));
  EXPECT_EQ(set(0x40, 0x01, 0x02, {0x09}), error(0x09));
  EXPECT_EQ(set(0x40, 0x01, 0x01, {0x88}), error(0x09));  // bits 3..5 "should be 0"
  EXPECT_EQ(set(0x40, 0x01, 0x10, {0x01}), error(0x0E));
}

TEST_F(Cdn127SlaveTest, ConfigurationResetPresets) {
  boot();
  allocate(0x01);
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), (ByteVec{0x85}));
  EXPECT_EQ(get(0x40, 0x01, 0x01), (ByteVec{0x8E, 0x81}));
  EXPECT_EQ(get(0x40, 0x01, 0x02), (ByteVec{0x8E, 0x08}));
  EXPECT_EQ(get(0x40, 0x01, 0x03), (ByteVec{0x8E, 0x08}));
  EXPECT_EQ(get(0x40, 0x01, 0x04), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x40, 0x01, 0x05), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x40, 0x01, 0x10), (ByteVec{0x8E, 0x02}));
  EXPECT_EQ(get(0x40, 0x01, 0x11), (ByteVec{0x8E, 0x03}));
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x00}), (ByteVec{0x85}));
  EXPECT_EQ(get(0x40, 0x01, 0x01), (ByteVec{0x8E, 0x86}));
  EXPECT_EQ(get(0x40, 0x01, 0x04), (ByteVec{0x8E, 0x02}));
  EXPECT_EQ(get(0x40, 0x01, 0x10), (ByteVec{0x8E, 0x06}));
  EXPECT_EQ(get(0x40, 0x01, 0x11), (ByteVec{0x8E, 0x04}));
  // bad preset, missing byte, class-level Reset (not listed)
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x02}), error(0x20));
  EXPECT_EQ(request({0x05, 0x40, 0x01}), error(0x13));
  EXPECT_EQ(request({0x05, 0x40, 0x00, 0x00}), error(0x08));
}

TEST_F(Cdn127SlaveTest, NoNcMaskInvertsReportedInputs) {
  boot();
  allocate();
  EXPECT_EQ(set(0x40, 0x01, 0x0A, {0x03}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  // 0x1E ^ 0x03 = 0x1D
  EXPECT_EQ(poll({0x00, 0x00, 0x00, 0x00})[1], 0x1D);
  EXPECT_EQ(get(0x08, 0x01, 0x03), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x08, 0x02, 0x03), (ByteVec{0x8E, 0x00}));
}

// ---------------------------------------------------------------------------
// Device Supervisor, exception status

TEST_F(Cdn127SlaveTest, ExceptionStatusFollowsThePumpAndTheEnables) {
  boot();
  allocate();
  EXPECT_EQ(get(0x32, 0x01, 0x0C), (ByteVec{0x8E, 0x80}));
  slave_->pump().set_alarm(true, now_);
  slave_->pump().set_warning(true);
  // Device Specific Error (bit 1) and Warning (bit 5), expanded mode bit 7
  EXPECT_EQ(get(0x32, 0x01, 0x0C), (ByteVec{0x8E, 0xA2}));
  EXPECT_EQ(get(0x32, 0x01, 0x0D), (ByteVec{0x8E, 2, 0, 0, 8, 8, 0, 8, 0, 2, 0, 1, 0, 1, 0x02}));
  EXPECT_EQ(get(0x32, 0x01, 0x0E), (ByteVec{0x8E, 2, 0, 0, 0, 1, 0x01}));
  // Clearing the alarm enable clears the alarm bits
  EXPECT_EQ(set(0x32, 0x01, 0x0F, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x32, 0x01, 0x0C), (ByteVec{0x8E, 0xA0}));
  EXPECT_EQ(get(0x32, 0x01, 0x0D).back(), 0x00);
  EXPECT_EQ(set(0x32, 0x01, 0x10, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x32, 0x01, 0x0C), (ByteVec{0x8E, 0x80}));
  EXPECT_EQ(set(0x32, 0x01, 0x10, {0x02}), error(0x09));
  // N2 flow failure is a device specific error too
  EXPECT_EQ(set(0x32, 0x01, 0x0F, {0x01}), (ByteVec{0x90}));
  slave_->pump().set_alarm(false, now_);
  slave_->pump().set_n2_flow_ok(false);
  EXPECT_EQ(get(0x32, 0x01, 0x0C), (ByteVec{0x8E, 0x82}));
}

TEST_F(Cdn127SlaveTest, DeviceSupervisorStrings) {
  boot();
  allocate();
  EXPECT_EQ(get(0x32, 0x01, 0x03), (ByteVec{0x8E, 9, 'A', 'N', 'A', 'L', 'O', 'G', ' ', 'I', 'O'}));
  EXPECT_EQ(get(0x32, 0x01, 0x04), (ByteVec{0x8E, 8, 'E', '0', '0', '-', '0', '0', '0', '0'}));
  EXPECT_EQ(get(0x32, 0x01, 0x05),
            (ByteVec{0x8E, 11, 'D', '.', 'I', '.', 'P', '.', ' ', 'I', 'n', 'c', '.'}));
  EXPECT_EQ(get(0x32, 0x01, 0x06), (ByteVec{0x8E, 6, 'C', 'D', 'N', '1', '2', '7'}));
  EXPECT_EQ(get(0x32, 0x01, 0x07), (ByteVec{0x8E, 6, '0', '1', '.', '0', '0', '5'}));
  EXPECT_EQ(get(0x32, 0x01, 0x08), (ByteVec{0x8E, 6, '0', '1', '.', '0', '0', '0'}));
}

// ---------------------------------------------------------------------------
// DeviceNet object

TEST_F(Cdn127SlaveTest, DeviceNetObjectWithSwitchesInUse) {
  boot();
  allocate();
  EXPECT_EQ(get(0x03, 0x01, 0x01), (ByteVec{0x8E, 0x03}));
  EXPECT_EQ(get(0x03, 0x01, 0x02), (ByteVec{0x8E, 0x02}));
  EXPECT_EQ(get(0x03, 0x01, 0x06), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x03, 0x01, 0x08), (ByteVec{0x8E, 0x03}));
  EXPECT_EQ(get(0x03, 0x01, 0x09), (ByteVec{0x8E, 0x02}));
  // The switches govern: no software setting.
  EXPECT_EQ(set(0x03, 0x01, 0x01, {0x05}), error(0x0E));
  // Turning a switch is seen as "changed" until the next power-up.
  slave_->set_switches(4, 2);
  EXPECT_EQ(get(0x03, 0x01, 0x06), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x03, 0x01, 0x08), (ByteVec{0x8E, 0x04}));
  EXPECT_EQ(slave_->mac().value(), 3);
  // Bus-off counter: set forces 0; allocation info only through Allocate.
  EXPECT_EQ(set(0x03, 0x01, 0x04, {0x07}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x03, 0x01, 0x04), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(set(0x03, 0x01, 0x05, {0x03, 0x0A}), error(0x0E));
  EXPECT_EQ(set(0x03, 0x01, 0x03, {0x01}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x03, 0x01, 0x03), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x03, 0x00, 0x01), (ByteVec{0x8E, 0x02, 0x00}));
  EXPECT_EQ(get(0x03, 0x00, 0x02), error(0x14));
}

TEST_F(Cdn127SlaveTest, SwitchAttributesNotSupportedInProgramPosition) {
  SlaveOptions o = default_options();
  o.mac_switch = 99;
  o.baud_switch = 9;
  o.stored_mac = 3;
  create(o);
  boot();
  allocate();
  for (std::uint8_t a = 6; a <= 9; ++a) EXPECT_EQ(get(0x03, 0x01, a), error(0x14)) << int(a);
  // Software MAC: the node answers, then comes back with its new MAC.
  EXPECT_EQ(set(0x03, 0x01, 0x01, {0x40}), error(0x09));
  auto out = exchange(kRequestId, {kMaster, 0x10, 0x03, 0x01, 0x01, 0x07});
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(hex(out[0]), "41B: 0A 90");
  EXPECT_EQ(hex(out[1]), "43F: 00 3B 00 34 12 00 00");  // duplicate MAC check for MAC 7
  EXPECT_EQ(slave_->mac().value(), 7);
  EXPECT_EQ(slave_->owner(), 255);
  // Baud: kept for the next power-up.
  advance(milliseconds(2001));
  EXPECT_EQ(single(0x43E, {kMaster, 0x4B, 0x03, 0x01, 0x01, kMaster}, 0x43B),
            (ByteVec{kMaster, 0xCB, 0x00}));
}

// ---------------------------------------------------------------------------
// Services and attributes the tables do not list

TEST_F(Cdn127SlaveTest, UnlistedServicesAndAttributesGiveTheirErrors) {
  boot();
  allocate();
  EXPECT_EQ(set(0x01, 0x01, 0x01, {0x01, 0x00}), error(0x08));  // Identity has no Set
  EXPECT_EQ(get(0x01, 0x01, 0x09), error(0x14));
  EXPECT_EQ(get(0x01, 0x02, 0x01), error(0x16));  // one instance
  EXPECT_EQ(get(0x07, 0x01, 0x01), error(0x16));  // no such class
  EXPECT_EQ(request({0x4B, 0x01, 0x01, 0x03, kMaster}), error(0x08));
  EXPECT_EQ(request({0x32, 0x01, 0x01}), error(0x08));  // unknown service code
  EXPECT_EQ(get(0x02, 0x00, 0x02), error(0x14));        // Router class: 1, 6, 7
  EXPECT_EQ(get(0x02, 0x00, 0x07), (ByteVec{0x8E, 0x02, 0x00}));
  EXPECT_EQ(get(0x02, 0x01, 0x02), (ByteVec{0x8E, 0x02, 0x00}));
  EXPECT_EQ(set(0x08, 0x01, 0x03, {0x01}), error(0x08));  // DIP: Get only
  EXPECT_EQ(get(0x08, 0x08, 0x03), error(0x16));          // DIP 1..7
  EXPECT_EQ(get(0x08, 0x07, 0x04), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x09, 0x03, 0x03), error(0x16));  // DOP: 2 of max 8
  EXPECT_EQ(get(0x09, 0x00, 0x02), (ByteVec{0x8E, 0x08, 0x00}));
  EXPECT_EQ(set(0x09, 0x01, 0x04, {0x00}), error(0x0E));  // DOP status
  EXPECT_EQ(set(0x09, 0x01, 0x05, {0x02}), error(0x09));
  EXPECT_EQ(set(0x09, 0x01, 0x05, {}), error(0x13));
  EXPECT_EQ(set(0x09, 0x01, 0x05, {0x01, 0x00}), error(0x15));
  EXPECT_EQ(set(0x0A, 0x01, 0x03, {0x00, 0x00}), error(0x0E));  // AIP: Set listed, nothing settable
  EXPECT_EQ(get(0x0A, 0x01, 0x07), (ByteVec{0x8E, 0x02}));
  EXPECT_EQ(set(0x0B, 0x01, 0x03, {0x00, 0x00}), error(0x0E));  // AOP value: Get
  EXPECT_EQ(set(0x0B, 0x01, 0x0B, {0x00, 0x10}), error(0x09));  // 4096
  EXPECT_EQ(set(0x0B, 0x01, 0x0B, {0xFF, 0x0F}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x04}), error(0x09));
  EXPECT_EQ(get(0x0B, 0x01, 0x04), error(0x14));
  EXPECT_EQ(set(0x04, 0x01, 0x03, {0x00}), error(0x0E));  // produced assembly
  EXPECT_EQ(set(0x04, 0x05, 0x03, {}), error(0x13));
  EXPECT_EQ(set(0x04, 0x05, 0x03, {0x01, 0x00}), error(0x15));
  EXPECT_EQ(get(0x04, 0x04, 0x03), error(0x16));
  EXPECT_EQ(get(0x04, 0x00, 0x02), (ByteVec{0x8E, 0x64, 0x00}));
  EXPECT_EQ(request({0x0E, 0x01, 0x01}), error(0x13));  // no attribute byte
  EXPECT_EQ(request({0x0E, 0x01, 0x01, 0x01, 0x00}), error(0x15));
  EXPECT_EQ(set(0x01, 0x00, 0x01, {0x01, 0x00}), error(0x08));  // class-level Set
}

TEST_F(Cdn127SlaveTest, EveryListedAttributeAnswersGet) {
  boot();
  establish_poll();
  for (const ClassDef& c : object_classes()) {
    for (const ClassAttributeDef& a : c.class_attributes) {
      const ByteVec r = get(c.id, 0, a.id);
      EXPECT_EQ(r, (ByteVec{0x8E, static_cast<std::uint8_t>(a.value & 0xFF),
                            static_cast<std::uint8_t>(a.value >> 8)}))
          << c.name << " class attribute " << int(a.id);
    }
    for (std::uint16_t inst = 1; inst <= 104; ++inst) {
      if (!c.has_instance(slave_->device(), inst)) continue;
      for (const AttributeDef& a : c.instance_attributes) {
        const ByteVec r = get(c.id, static_cast<std::uint8_t>(inst), a.id);
        ASSERT_FALSE(r.empty());
        EXPECT_EQ(r[0], 0x8E) << c.name << " " << inst << "/" << int(a.id) << ": " << hex(r);
      }
    }
  }
}

TEST_F(Cdn127SlaveTest, ConsumedAssemblySetDrivesOutputsUnlessThePollOwnsIt) {
  boot();
  allocate();
  // assembly 100: [outputs][analog LE]
  EXPECT_EQ(set(0x04, 0x64, 0x03, {0x04, 0x10, 0x00}), (ByteVec{0x90}));
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 16);
  EXPECT_EQ(slave_->pump().last_cause(), OutputCause::kExplicit);
  // assembly 5 carries no analog output: the analog value stays
  EXPECT_EQ(set(0x04, 0x05, 0x03, {0x01}), (ByteVec{0x90}));
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_FALSE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 16);
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(set(0x04, 0x68, 0x03, {0x00, 0x00, 0x00, 0x00}), error(0x0C));
  // produced assemblies read the inputs
  EXPECT_EQ(get(0x04, 0x01, 0x03), (ByteVec{0x8E, 0x80}));
  EXPECT_EQ(get(0x04, 0x03, 0x03), (ByteVec{0x8E, 0x1E}));
  EXPECT_EQ(get(0x04, 0x66, 0x03), (ByteVec{0x8E, 0x1E, 0x00, 0x00, 0x00, 0x00, 0x00}));
}

TEST_F(Cdn127SlaveTest, GroupsAndMessagesNotSupportedAreIgnored) {
  boot();
  allocate();
  // Group 3 UCMM request from MAC 10, Group 1 traffic, bit strobe from the master,
  // another slave's poll command.
  EXPECT_TRUE(exchange(0x78A, {0x00, 0x4B, 0x03, 0x01, 0x03, 0x0A}).empty());
  EXPECT_TRUE(exchange(0x3C5, {0x01}).empty());
  EXPECT_TRUE(exchange(0x450, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}).empty());
  EXPECT_TRUE(exchange(0x42D, {0x01, 0x00, 0x00, 0x00}).empty());
  EXPECT_TRUE(exchange(0x41A, {0x00}).empty());  // COS ack to our MAC
  // The master's bit strobe is for every node it owns: ignored by a device
  // without a bit-strobe connection; a bit strobe of another master is not
  // addressed to it.
  EXPECT_TRUE(exchange(0x458, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}).empty());
  EXPECT_EQ(slave_->counters().frames_ignored, 3u);
  EXPECT_EQ(slave_->counters().frames_not_addressed, 3u);
}

// ---------------------------------------------------------------------------
// Factory output actions (SlaveOptions::factory_output_actions)

// The simulator's factory values: every attribute 0, each DOP to Off on a
// fault and on idle, the AOP holding.
TEST_F(Cdn127SlaveTest, DefaultFactoryOutputActionsTurnTheDopsOff) {
  boot();
  allocate();
  for (std::uint8_t instance : kDopInstances) {
    for (std::uint8_t attribute = 5; attribute <= 8; ++attribute) {
      EXPECT_EQ(get(0x09, instance, attribute), (ByteVec{0x8E, 0x00})) << int{attribute};
    }
  }
  EXPECT_EQ(get(0x0B, 0x01, 0x09), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x0B, 0x01, 0x0A), (ByteVec{0x8E, 0x00}));
}

TEST_F(Cdn127SlaveTest, UnsafeFactoryOutputActionsAreWhatTheDeviceAnswers) {
  create(unsafe_options());
  boot();
  allocate();
  for (std::uint8_t instance : kDopInstances) {
    EXPECT_EQ(get(0x09, instance, 0x05), (ByteVec{0x8E, 0x01}));  // fault action: no change
    EXPECT_EQ(get(0x09, instance, 0x06), (ByteVec{0x8E, 0x00}));
    EXPECT_EQ(get(0x09, instance, 0x07), (ByteVec{0x8E, 0x01}));  // idle action: no change
    EXPECT_EQ(get(0x09, instance, 0x08), (ByteVec{0x8E, 0x00}));
  }
  EXPECT_EQ(get(0x0B, 0x01, 0x09), (ByteVec{0x8E, 0x00}));  // fault state: hold
  EXPECT_EQ(get(0x0B, 0x01, 0x0A), (ByteVec{0x8E, 0x00}));  // idle state: hold
}

// The unsafe device going idle keeps the pump on, until a master writes an
// idle action of its own over the explicit connection.
TEST_F(Cdn127SlaveTest, UnsafeDeviceKeepsThePumpOnWhenIdleUntilToldOtherwise) {
  create(unsafe_options());
  boot();
  establish_poll();
  poll({0x05, 0x00, 0x34, 0x02});  // pump on, ballast on, 0x234
  ASSERT_TRUE(slave_->outputs().pump_on);

  EXPECT_EQ(poll({}).size(), 6u);
  EXPECT_EQ(slave_->counters().polls_idle, 1u);
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0234);

  // DOP 1 Idle Action 0 (use the value), Idle Value 0 (Off).
  EXPECT_EQ(set(0x09, 0x01, 0x07, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x09, 0x01, 0x08, {0x00}), (ByteVec{0x90}));
  poll({0x05, 0x00, 0x34, 0x02});
  ASSERT_TRUE(slave_->outputs().pump_on);
  poll({});
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);  // DOP 2 still holds
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0234);
  EXPECT_TRUE(slave_->pump().last_change_was_idle());
}

// A poll connection timing out (the fault condition): the unsafe device holds
// every output; once told to use its fault values, it takes them.
TEST_F(Cdn127SlaveTest, UnsafeDeviceHoldsOnPollTimeoutUntilGivenFaultValues) {
  create(unsafe_options());
  boot();
  establish_poll(100);
  poll({0x05, 0x00, 0x34, 0x02});
  advance(milliseconds(400));
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0234);
  EXPECT_TRUE(slave_->pump().last_change_was_fault());

  // DOP 1 Fault Action 0 with Fault Value 0; AOP Fault State 3 with Fault Value 500.
  EXPECT_EQ(set(0x09, 0x01, 0x05, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x09, 0x01, 0x06, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x03}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x0B, {0xF4, 0x01}), (ByteVec{0x90}));
  EXPECT_EQ(request({0x05, 0x05, 0x02}), (ByteVec{0x85}));  // Connection Reset
  poll({0x05, 0x00, 0x34, 0x02});
  advance(milliseconds(400));
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);  // DOP 2 still holds
  EXPECT_EQ(slave_->outputs().analog_out_raw, 500);
}

// Identity Reset type 1 brings back the factory values, unsafe ones included.
TEST_F(Cdn127SlaveTest, FactoryResetRestoresTheUnsafeOutputActions) {
  create(unsafe_options());
  boot();
  allocate();
  EXPECT_EQ(set(0x09, 0x01, 0x07, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x0A, {0x01}), (ByteVec{0x90}));
  exchange(kRequestId, {kMaster, 0x05, 0x01, 0x01, 0x01});
  advance(milliseconds(2001));
  allocate();
  EXPECT_EQ(get(0x09, 0x01, 0x07), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x0B, 0x01, 0x0A), (ByteVec{0x8E, 0x00}));
}

// ---------------------------------------------------------------------------
// Identity faults (Cdn127Device::set_faults, cdn127-sim's `fault` command)

TEST_F(Cdn127SlaveTest, IdentityFaultsShowInStatusAndState) {
  boot();
  allocate();
  auto& device = slave_->device();
  struct Case {
    IdentityFaults faults;
    ByteVec status;  // attribute 5, owned (bit 0) included
    std::uint8_t state;
    std::uint8_t supervisor;  // Device Supervisor attribute 11
  };
  const Case cases[] = {
      {{.minor_recoverable = true}, {0x01, 0x01}, 3, 2},
      {{.minor_unrecoverable = true}, {0x01, 0x02}, 3, 2},
      {{.major_recoverable = true}, {0x01, 0x04}, 4, 5},    // Abort
      {{.major_unrecoverable = true}, {0x01, 0x08}, 5, 6},  // Critical Fault
      {{.major_recoverable = true, .major_unrecoverable = true}, {0x01, 0x0C}, 5, 6},
  };
  for (const Case& c : cases) {
    device.set_faults(c.faults, now_);
    ByteVec status{0x8E};
    status.insert(status.end(), c.status.begin(), c.status.end());
    EXPECT_EQ(get(0x01, 0x01, 0x05), status) << hex(status);
    EXPECT_EQ(get(0x01, 0x01, 0x08), (ByteVec{0x8E, c.state})) << hex(status);
    EXPECT_EQ(get(0x32, 0x01, 0x0B), (ByteVec{0x8E, c.supervisor})) << hex(status);
    device.set_faults({}, now_);
    EXPECT_EQ(get(0x01, 0x01, 0x05), (ByteVec{0x8E, 0x01, 0x00}));
    EXPECT_EQ(get(0x01, 0x01, 0x08), (ByteVec{0x8E, 0x03}));  // operating again
    EXPECT_EQ(get(0x32, 0x01, 0x0B), (ByteVec{0x8E, 0x02}));
  }
  // The short circuit of the minor recoverable fault is a DOP's Status too.
  device.set_faults({.minor_recoverable = true}, now_);
  EXPECT_EQ(get(0x09, 0x01, 0x04), (ByteVec{0x8E, 0x01}));
}

// A major fault applies the fault actions and holds the outputs there: polls
// are answered (the master still reads the inputs) but not applied, and
// output Sets are refused, until it clears.
TEST_F(Cdn127SlaveTest, MajorFaultAppliesTheFaultActionsAndHoldsTheOutputs) {
  boot();
  allocate();
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x01}), (ByteVec{0x90}));  // AOP fault state: low
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  poll({0x05, 0x00, 0x34, 0x02});
  ASSERT_TRUE(slave_->outputs().pump_on);

  slave_->device().set_faults({.major_recoverable = true}, now_);
  EXPECT_FALSE(slave_->outputs().pump_on);  // fault value Off
  EXPECT_FALSE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0);
  EXPECT_TRUE(slave_->pump().last_change_was_fault());

  EXPECT_EQ(poll({0x05, 0x00, 0x34, 0x02}).size(), 6u);
  EXPECT_EQ(poll({}).size(), 6u);
  EXPECT_EQ(slave_->counters().polls_major_fault, 2u);
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->pump().last_change_was_fault());
  EXPECT_EQ(set(0x09, 0x01, 0x03, {0x01}), error(0x10));  // device state conflict
  EXPECT_EQ(set(0x04, 0x05, 0x03, {0x01}), error(0x10));  // consumed assembly 5
  EXPECT_FALSE(slave_->outputs().pump_on);

  // A second major fault on top applies nothing new; clearing one leaves the
  // other in force.
  slave_->device().set_faults({.major_recoverable = true, .major_unrecoverable = true}, now_);
  slave_->device().set_faults({.major_unrecoverable = true}, now_);
  poll({0x05, 0x00, 0x34, 0x02});
  EXPECT_FALSE(slave_->outputs().pump_on);

  slave_->device().set_faults({}, now_);
  EXPECT_FALSE(slave_->outputs().pump_on);  // nothing is switched back on by itself
  poll({0x05, 0x00, 0x34, 0x02});
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0234);
  EXPECT_EQ(slave_->counters().polls_major_fault, 3u);
}

// With the unsafe factory actions a major fault leaves the pump on: what
// the device was told to do on a fault.
TEST_F(Cdn127SlaveTest, MajorFaultOnAnUnsafeDeviceHoldsThePumpOn) {
  create(unsafe_options());
  boot();
  establish_poll();
  poll({0x01, 0x00, 0x00, 0x00});
  slave_->device().set_faults({.major_recoverable = true}, now_);
  EXPECT_TRUE(slave_->outputs().pump_on);
  poll({});  // idle actions held off too
  EXPECT_TRUE(slave_->outputs().pump_on);
}

// Minor faults change no output.
TEST_F(Cdn127SlaveTest, MinorFaultsLeaveTheOutputsToTheMaster) {
  boot();
  establish_poll();
  poll({0x01, 0x00, 0x00, 0x00});
  slave_->device().set_faults({.minor_recoverable = true, .minor_unrecoverable = true}, now_);
  EXPECT_TRUE(slave_->outputs().pump_on);
  poll({0x00, 0x00, 0x00, 0x00});
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->counters().polls_major_fault, 0u);
}

}  // namespace
}  // namespace dnbridge::sim
