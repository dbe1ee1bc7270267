// cdn127-sim's control language.
#include "adapters/sim/host/control.hpp"

#include <gtest/gtest.h>

namespace dnbridge::sim::host {
namespace {

ControlCommand ok(std::string_view line) {
  auto r = parse_control(line);
  if (auto* e = std::get_if<std::string>(&r)) ADD_FAILURE() << line << ": " << *e;
  if (std::holds_alternative<ControlCommand>(r)) return std::get<ControlCommand>(r);
  ADD_FAILURE() << line << ": parsed to nothing";
  return {};
}

std::string error(std::string_view line) {
  auto r = parse_control(line);
  if (auto* e = std::get_if<std::string>(&r)) return *e;
  ADD_FAILURE() << line << ": accepted";
  return {};
}

TEST(Control, DigitalInputs) {
  auto c = ok("set 5 alarm on");
  EXPECT_EQ(c.verb, Verb::kSet);
  EXPECT_EQ(c.mac, 5);
  EXPECT_EQ(c.input, Input::kAlarm);
  EXPECT_TRUE(c.on);
  c = ok("  set 63\tinterlock off\r");
  EXPECT_EQ(c.mac, 63);
  EXPECT_EQ(c.input, Input::kInterlock);
  EXPECT_FALSE(c.on);
  EXPECT_EQ(ok("set 1 n2-flow fail").input, Input::kN2Flow);
  EXPECT_EQ(ok("set 1 warning 1").input, Input::kWarning);
}

TEST(Control, AnalogInputsInVoltsOrCounts) {
  auto c = ok("set 5 ain1 2.5V");
  EXPECT_EQ(c.input, Input::kAnalog1);
  EXPECT_NEAR(c.raw, 1024, 1);  // 2.5 V of 10 V full scale, 12 bits
  c = ok("set 5 ain2 4095");
  EXPECT_EQ(c.input, Input::kAnalog2);
  EXPECT_EQ(c.raw, 4095);
  EXPECT_EQ(ok("set 5 ain1 0v").raw, 0);
}

TEST(Control, PowerAndStatus) {
  auto c = ok("power-cycle 6");
  EXPECT_EQ(c.verb, Verb::kPowerCycle);
  EXPECT_EQ(c.mac, 6);
  c = ok("power-off all");
  EXPECT_EQ(c.verb, Verb::kPowerOff);
  EXPECT_FALSE(c.mac.has_value());
  EXPECT_EQ(ok("power-on 6").verb, Verb::kPowerOn);
  EXPECT_FALSE(ok("status").mac.has_value());
  EXPECT_EQ(ok("status 7").mac, 7);
  EXPECT_EQ(ok("quit").verb, Verb::kQuit);
  EXPECT_EQ(ok("help").verb, Verb::kHelp);
}

TEST(Control, IdentityFaults) {
  auto c = ok("fault 5 major-recoverable on");
  EXPECT_EQ(c.verb, Verb::kFault);
  EXPECT_EQ(c.mac, 5);
  EXPECT_EQ(c.fault, Fault::kMajorRecoverable);
  EXPECT_TRUE(c.on);
  c = ok("fault all major-unrecoverable off");
  EXPECT_FALSE(c.mac.has_value());
  EXPECT_EQ(c.fault, Fault::kMajorUnrecoverable);
  EXPECT_FALSE(c.on);
  EXPECT_EQ(ok("fault 0 minor-recoverable on").fault, Fault::kMinorRecoverable);
  EXPECT_EQ(ok("fault 63 minor-unrecoverable on").fault, Fault::kMinorUnrecoverable);
}

TEST(Control, AParameterOfADeviceDrivenByItsEds) {
  auto c = ok("set 21 param 3 90");
  EXPECT_EQ(c.verb, Verb::kSet);
  EXPECT_EQ(c.mac, 21);
  EXPECT_EQ(c.input, Input::kParam);
  EXPECT_EQ(c.param, 3u);
  EXPECT_EQ(c.value, 90.0);
  EXPECT_EQ(ok("set 21 param 2 -2.5").value, -2.5);
  EXPECT_EQ(ok("set 21 param 3 0x5A").value, 90.0);
}

TEST(Control, BlankAndCommentLinesAreNothing) {
  EXPECT_TRUE(std::holds_alternative<std::monostate>(parse_control("")));
  EXPECT_TRUE(std::holds_alternative<std::monostate>(parse_control("   \t")));
  EXPECT_TRUE(std::holds_alternative<std::monostate>(parse_control("# a comment")));
}

TEST(Control, ErrorsSayWhatIsWrong) {
  EXPECT_EQ(error("set 64 alarm on"), "\"64\" is not a MAC ID (0..63)");
  EXPECT_EQ(error("set all alarm on"), "\"all\" is not a MAC ID (0..63)");
  EXPECT_EQ(error("set 5 alarm maybe"), "\"maybe\" is not on or off");
  EXPECT_EQ(error("set 5 ain1 10.5V"), "10.5V is outside 0..10 V");
  EXPECT_EQ(error("set 5 ain1 4096"), "\"4096\" is neither volts (\"2.5V\") nor counts 0..4095");
  EXPECT_EQ(error("set 5 ain1 xV"), "\"xV\" is not a voltage");
  EXPECT_EQ(error("set 5 fan on"),
            "unknown input \"fan\": alarm, warning, n2-flow, interlock, ain1, ain2");
  EXPECT_EQ(error("set 5 alarm"), "usage: set MAC INPUT VALUE, or set MAC param N VALUE");
  EXPECT_EQ(error("set 21 param 0 1"), "\"0\" is not a parameter number (1..65535)");
  EXPECT_EQ(error("set 21 param 3 x"), "\"x\" is not a number");
  EXPECT_EQ(error("power-cycle"), "usage: power-cycle MAC|all");
  EXPECT_EQ(error("reboot 5"), "unknown command \"reboot\" (help lists them)");
  EXPECT_EQ(error("power-on 5 6"), "usage: power-on MAC|all");
  EXPECT_EQ(error("fault 5 major-recoverable"), "usage: fault MAC|all FAULT on|off");
  EXPECT_EQ(error("fault 64 major-recoverable on"), "\"64\" is not a MAC ID (0..63 or all)");
  EXPECT_EQ(error("fault 5 major on"),
            "unknown fault \"major\": minor-recoverable, minor-unrecoverable, "
            "major-recoverable, major-unrecoverable");
  // "ok" would read backwards for a fault: only on and off.
  EXPECT_EQ(error("fault 5 minor-recoverable ok"), "\"ok\" is not on or off");
}

}  // namespace
}  // namespace dnbridge::sim::host
