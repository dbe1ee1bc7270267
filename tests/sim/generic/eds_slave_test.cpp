// A simulated slave described by the example I/O block EDS on the in-process
// bus, fake clock, with a test node speaking to it frame by frame (no master
// of the product's). Its change-of-state connection produces on Group 1
// message 13, is acknowledged by the test node on Group 2 message 2, and
// retries when it is not. What the product's master never does (paths
// refused, the change-of-state connection reset, timed out or given a new
// rate, a Release of odd choices) the test node does too. The master brings
// it online in tests/integration/master_eds_slave_test.cpp.
#include "adapters/sim/generic/eds_slave.hpp"

#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "adapters/sim/world/sim_eds_slave.hpp"
#include "adapters/sim/world/sim_world.hpp"
#include "bridge/devicenet/wire/identifier.hpp"
#include "support/example_eds.hpp"

namespace dnbridge::test {
namespace {

using devicenet::MacId;

constexpr unsigned kSlaveMac = 5;
constexpr unsigned kMasterMac = 0;
// Example I/O block: Assembly 100 (inputs: Param3 DI, Param5 status, Param2
// AI) and 150 (outputs: Param4 DO, a pad byte).
constexpr std::uint16_t kInputs = 100;
constexpr std::uint16_t kOutputs = 150;

MacId mac(unsigned v) { return MacId::from(v).value(); }

// A node the test speaks through: records what it hears, sends what it is told.
class TestNode final : public sim::SimEndpoint {
 public:
  explicit TestNode(sim::SimWorld& world) : world_(world), handle_(world.bus().attach(*this)) {
    world_.add(*this);
  }
  ~TestNode() override {
    world_.remove(*this);
    (void)world_.bus().detach(handle_);
  }
  TestNode(const TestNode&) = delete;
  TestNode& operator=(const TestNode&) = delete;

  void on_frame(const can::CanFrame& frame, TimePoint rx_time) override {
    heard.push_back({frame, rx_time});
    if (auto_ack && frame.id == cos_id()) send(ack_frame());
  }
  TimePoint next_deadline() const override { return kNever; }
  void on_timer(TimePoint) override {}

  void send(const can::CanFrame& frame) { world_.bus().sink(handle_).send(frame, world_.now()); }
  static can::CanFrame frame(std::uint32_t id, std::vector<std::uint8_t> data) {
    return can::CanFrame::make(id, Bytes(data.data(), data.size())).value();
  }
  static std::uint32_t cos_id() {
    return devicenet::group1_id(devicenet::Group1Message::kSlaveCosCyclic, mac(kSlaveMac));
  }
  static can::CanFrame ack_frame() {
    return frame(
        devicenet::group2_id(mac(kSlaveMac), devicenet::Group2Message::kMasterCosCyclicAck), {});
  }
  // The frames heard with `id`, and their times.
  std::vector<std::pair<can::CanFrame, TimePoint>> with_id(std::uint32_t id) const {
    std::vector<std::pair<can::CanFrame, TimePoint>> out;
    for (const auto& h : heard) {
      if (h.first.id == id) out.push_back(h);
    }
    return out;
  }

  bool auto_ack = false;
  std::vector<std::pair<can::CanFrame, TimePoint>> heard;

 private:
  sim::SimWorld& world_;
  sim::NodeHandle handle_;
};

// --- change of state ------------------------------------------------------------

class EdsSlaveChangeOfState : public ::testing::Test {
 protected:
  EdsSlaveChangeOfState()
      : slave_(world_, test::example_eds(test::kIoBlockEds), options(), world_.now()),
        tester_(world_) {}
  static sim::EdsSlaveOptions options() {
    sim::EdsSlaveOptions o;
    o.mac = kSlaveMac;
    return o;
  }
  sim::EdsSlave& slave() { return slave_.device(); }
  std::uint32_t request_id() {
    return devicenet::group2_id(mac(kSlaveMac), devicenet::Group2Message::kMasterExplicitRequest);
  }
  // Allocates explicit + `cos_choice` from the test node (MAC 0), and sets
  // instance 4's EPR: the connection is established.
  void establish(std::uint8_t cos_choice, std::uint16_t epr_ms) {
    ASSERT_TRUE(world_.run_until(
        [&] { return slave().network_state() == sim::Group2Slave::NetworkState::kOnline; },
        seconds(5)));
    tester_.send(TestNode::frame(
        devicenet::group2_id(mac(kSlaveMac), devicenet::Group2Message::kUnconnectedExplicitRequest),
        {0x00, 0x4B, 0x03, 0x01, static_cast<std::uint8_t>(0x01 | cos_choice), 0x00}));
    world_.run_for(milliseconds(10));
    ASSERT_EQ(slave().cos_state(), sim::ConnectionState::kConfiguring);
    // Set_Attribute_Single Connection 4 attribute 9.
    tester_.send(TestNode::frame(request_id(),
                                 {0x00, 0x10, 0x05, 0x04, 0x09, static_cast<std::uint8_t>(epr_ms),
                                  static_cast<std::uint8_t>(epr_ms >> 8)}));
    world_.run_for(milliseconds(10));
    ASSERT_EQ(slave().cos_state(), sim::ConnectionState::kEstablished);
    established_ = world_.now();
  }
  void change_inputs(std::uint8_t di) {
    const std::array<std::uint8_t, 1> v{di};
    ASSERT_TRUE(slave().objects().set_param_value(3, Bytes(v)));
    slave().inputs_changed(world_.now());
  }

  sim::SimWorld world_;
  sim::SimEdsSlave slave_;
  TestNode tester_;
  TimePoint established_{};
};

TEST_F(EdsSlaveChangeOfState, AChangeIsProducedOnMessage13AndTheAckStopsRetries) {
  establish(0x10, 1000);
  tester_.auto_ack = true;
  tester_.heard.clear();
  change_inputs(0x5A);
  world_.run_for(milliseconds(200));
  const auto cos = tester_.with_id(TestNode::cos_id());
  ASSERT_EQ(cos.size(), 1u);
  EXPECT_EQ(cos[0].first.id, 0x340u + kSlaveMac);
  EXPECT_EQ(std::vector<std::uint8_t>(cos[0].first.payload().begin(), cos[0].first.payload().end()),
            slave().objects().assembly_data(kInputs));
  EXPECT_EQ(cos[0].first.payload()[0], 0x5A);
  EXPECT_EQ(slave().cos_counters().produced, 1u);
  EXPECT_EQ(slave().cos_counters().acks_received, 1u);
  EXPECT_EQ(slave().cos_counters().retries, 0u);
  // The heartbeat: the data again an EPR after, acknowledged too.
  world_.run_for(milliseconds(1000));
  EXPECT_EQ(tester_.with_id(TestNode::cos_id()).size(), 2u);
  EXPECT_EQ(slave().cos_counters().retries, 0u);
  EXPECT_EQ(slave().cos_state(), sim::ConnectionState::kEstablished);
  // Connection 4 as the master reads it: produced on 0x340 + MAC, consumed on
  // Group 2 message 2, 4 bytes produced.
  tester_.send(TestNode::frame(request_id(), {0x00, 0x0E, 0x05, 0x04, 0x04}));
  tester_.send(TestNode::frame(request_id(), {0x00, 0x0E, 0x05, 0x04, 0x07}));
  world_.run_for(milliseconds(20));
  const auto answers = tester_.with_id(
      devicenet::group2_id(mac(kSlaveMac), devicenet::Group2Message::kSlaveExplicitResponse));
  ASSERT_GE(answers.size(), 2u);
  const auto& produced_id = answers[answers.size() - 2].first;
  const auto& size = answers.back().first;
  EXPECT_EQ(std::vector<std::uint8_t>(produced_id.payload().begin(), produced_id.payload().end()),
            (std::vector<std::uint8_t>{0x00, 0x8E, 0x45, 0x03}));
  EXPECT_EQ(std::vector<std::uint8_t>(size.payload().begin(), size.payload().end()),
            (std::vector<std::uint8_t>{0x00, 0x8E, 0x04, 0x00}));
}

TEST_F(EdsSlaveChangeOfState, WithoutAckTheMessageIsRetriedUpToTheRetryLimit) {
  // Acknowledge Handler: timer 20 ms, retry limit 3 (attribute 2, set before
  // the connection is established).
  slave().objects().ack_handler().retry_limit = 3;
  establish(0x10, 1000);
  tester_.heard.clear();
  change_inputs(0x11);
  world_.run_for(milliseconds(200));
  const auto cos = tester_.with_id(TestNode::cos_id());
  // The message, then 3 retries 20 ms apart; then given up.
  ASSERT_EQ(cos.size(), 4u);
  EXPECT_EQ(cos[1].second - cos[0].second, milliseconds(20));
  EXPECT_EQ(cos[3].second - cos[2].second, milliseconds(20));
  EXPECT_EQ(slave().cos_counters().produced, 4u);
  EXPECT_EQ(slave().cos_counters().retries, 3u);
  EXPECT_EQ(slave().cos_counters().given_up, 1u);
  EXPECT_EQ(slave().cos_counters().acks_received, 0u);
  // An acknowledgment of the next change after 5 ms stops its retries at
  // once.
  change_inputs(0x12);
  world_.run_for(milliseconds(5));
  tester_.send(TestNode::ack_frame());
  world_.run_for(milliseconds(200));
  EXPECT_EQ(tester_.with_id(TestNode::cos_id()).size(), 5u);
  EXPECT_EQ(slave().cos_counters().retries, 3u);
  EXPECT_EQ(slave().cos_counters().acks_received, 1u);
}

TEST_F(EdsSlaveChangeOfState, AckSuppressionAndAllocationRefusals) {
  ASSERT_TRUE(world_.run_until(
      [&] { return slave().network_state() == sim::Group2Slave::NetworkState::kOnline; },
      seconds(5)));
  const auto allocate = [&](std::uint8_t choice) {
    tester_.heard.clear();
    tester_.send(TestNode::frame(
        devicenet::group2_id(mac(kSlaveMac), devicenet::Group2Message::kUnconnectedExplicitRequest),
        {0x00, 0x4B, 0x03, 0x01, choice, 0x00}));
    world_.run_for(milliseconds(10));
    const auto r = tester_.with_id(
        devicenet::group2_id(mac(kSlaveMac), devicenet::Group2Message::kSlaveExplicitResponse));
    return r.empty() ? std::vector<std::uint8_t>{}
                     : std::vector<std::uint8_t>(r[0].first.payload().begin(),
                                                 r[0].first.payload().end());
  };
  // Acknowledge suppression alone, COS and cyclic together, bit-strobe: refused.
  EXPECT_EQ(allocate(0x41), (std::vector<std::uint8_t>{0x00, 0x94, 0x09, 0x02}));
  EXPECT_EQ(allocate(0x31), (std::vector<std::uint8_t>{0x00, 0x94, 0x09, 0x02}));
  EXPECT_EQ(allocate(0x05), (std::vector<std::uint8_t>{0x00, 0x94, 0x02, 0x02}));
  // Cyclic with acknowledgment suppressed: taken; no acks, no retries.
  EXPECT_EQ(allocate(0x61), (std::vector<std::uint8_t>{0x00, 0xCB, 0x00}));
  EXPECT_EQ(slave().connections().allocation_choice(), 0x61);
  tester_.send(TestNode::frame(request_id(), {0x00, 0x10, 0x05, 0x04, 0x09, 100, 0}));
  world_.run_for(milliseconds(350));
  // Cyclic: every EPR, whatever the data.
  EXPECT_EQ(tester_.with_id(TestNode::cos_id()).size(), 3u);
  EXPECT_EQ(slave().cos_counters().retries, 0u);
  EXPECT_FALSE(slave().objects().ack_handler().cos_acknowledged);
}

// --- frame by frame ------------------------------------------------------------

// `text` with `from` replaced by `to` once; a test failure if it is not there.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

profiles::eds::EdsFile parsed(const std::string& text) {
  auto r = profiles::eds::parse(text);
  EXPECT_TRUE(r.file.has_value());
  return r.file.value_or(profiles::eds::EdsFile{});
}

// The example I/O block with its input (Input1, Assembly 100) 10 bytes long:
// 48 bits of padding after the analog input.
profiles::eds::EdsFile io_block_with_long_input() {
  std::string t = test::example_eds_text(test::kIoBlockEds);
  t = replaced(t, "4,                      $ size in bytes", "10,");
  t = replaced(t, "32,                     $ size in bits", "80,");
  t = replaced(t, "16, Param2;", "16, Param2, 48, ;");
  return parsed(t);
}

// The same with its output (Output1, Assembly 150) 10 bytes long.
profiles::eds::EdsFile io_block_with_long_output() {
  std::string t = test::example_eds_text(test::kIoBlockEds);
  t = replaced(t, "Output1 =\n                2,", "Output1 =\n                10,");
  t = replaced(t, "\n                16,\n", "\n                80,\n");
  t = replaced(t, "8, ;", "8, , 64, ;");
  return parsed(t);
}

// The example I/O block with a second output, Output2: Assembly 151, the
// input filter (Param1, 2 bytes) as a master may set it on every poll.
constexpr std::uint16_t kOutputs2 = 151;
profiles::eds::EdsFile io_block_with_two_outputs() {
  std::string t = test::example_eds_text(test::kIoBlockEds);
  t = replaced(t, R"("Digital outputs 0..7, then a pad byte";)",
               R"("Digital outputs 0..7, then a pad byte";
        Output2 = 2, 0, 0x0001, "Filter", 6, "20 04 24 97 30 03", "Param1";)");
  t += R"(
        Assem151 = "Filter", "20 04 24 97 30 03", 16, 0x0000, ,, 16, Param1;
)";
  return parsed(t);
}

// The slave and a test node at MAC 0 that speaks to it frame by frame.
class EdsSlaveByFrames : public ::testing::Test {
 protected:
  EdsSlaveByFrames() : tester_(world_) {}

  void start(profiles::eds::EdsFile file = test::example_eds(test::kIoBlockEds)) {
    sim::EdsSlaveOptions o;
    o.mac = kSlaveMac;
    slave_.emplace(world_, std::move(file), o, world_.now());
    ASSERT_TRUE(world_.run_until(
        [&] { return slave().network_state() == sim::Group2Slave::NetworkState::kOnline; },
        seconds(5)));
  }
  sim::EdsSlave& slave() { return slave_->device(); }
  std::optional<double> param(unsigned n) { return slave().objects().param_number(n); }
  void set_param(unsigned n, std::vector<std::uint8_t> value) {
    ASSERT_TRUE(slave().objects().set_param_value(n, Bytes(value.data(), value.size())));
  }

  static std::uint32_t id(devicenet::Group2Message m) {
    return devicenet::group2_id(mac(kSlaveMac), m);
  }
  // The last explicit response heard since `from` (service byte first;
  // fragment acks skipped); empty if none.
  std::vector<std::uint8_t> response_since(std::size_t from) const {
    std::vector<std::uint8_t> out;
    for (std::size_t i = from; i < tester_.heard.size(); ++i) {
      const can::CanFrame& f = tester_.heard[i].first;
      if (f.id != id(devicenet::Group2Message::kSlaveExplicitResponse) || f.len == 0 ||
          (f.data[0] & 0x80) != 0) {
        continue;
      }
      out.assign(f.payload().begin() + 1, f.payload().end());
    }
    return out;
  }
  // An explicit request (service byte first) on the explicit connection, in
  // fragments over 7 bytes; its response.
  std::vector<std::uint8_t> request(const std::vector<std::uint8_t>& message) {
    const std::size_t from = tester_.heard.size();
    const auto to = id(devicenet::Group2Message::kMasterExplicitRequest);
    if (message.size() <= 7) {
      std::vector<std::uint8_t> p{0x00};
      p.insert(p.end(), message.begin(), message.end());
      tester_.send(TestNode::frame(to, p));
    } else {
      // [0x80: fragmented, MAC 0][type first 0x00 / middle 0x40 / last 0x80 | count][6 bytes]
      for (std::size_t at = 0, count = 0; at < message.size(); at += 6, ++count) {
        const std::size_t n = std::min<std::size_t>(6, message.size() - at);
        const std::uint8_t type = at == 0 ? 0x00 : at + n == message.size() ? 0x80 : 0x40;
        std::vector<std::uint8_t> p{0x80, static_cast<std::uint8_t>(type | count)};
        p.insert(p.end(), message.begin() + static_cast<std::ptrdiff_t>(at),
                 message.begin() + static_cast<std::ptrdiff_t>(at + n));
        tester_.send(TestNode::frame(to, p));
        world_.run_for(milliseconds(2));
      }
    }
    world_.run_for(milliseconds(10));
    return response_since(from);
  }
  // Allocate and Release on the unconnected port (DeviceNet object, instance 1).
  std::vector<std::uint8_t> allocate(std::uint8_t choice) {
    const std::size_t from = tester_.heard.size();
    tester_.send(TestNode::frame(id(devicenet::Group2Message::kUnconnectedExplicitRequest),
                                 {0x00, 0x4B, 0x03, 0x01, choice, kMasterMac}));
    world_.run_for(milliseconds(10));
    return response_since(from);
  }
  std::vector<std::uint8_t> release(std::uint8_t choice) {
    const std::size_t from = tester_.heard.size();
    tester_.send(TestNode::frame(id(devicenet::Group2Message::kUnconnectedExplicitRequest),
                                 {0x00, 0x4C, 0x03, 0x01, choice}));
    world_.run_for(milliseconds(10));
    return response_since(from);
  }
  // Connection object (class 5): Get and Set of an attribute, Reset.
  std::vector<std::uint8_t> get(std::uint8_t instance, std::uint8_t attribute) {
    return request({0x0E, 0x05, instance, attribute});
  }
  std::vector<std::uint8_t> set(std::uint8_t instance, std::uint8_t attribute,
                                std::vector<std::uint8_t> data) {
    std::vector<std::uint8_t> m{0x10, 0x05, instance, attribute};
    m.insert(m.end(), data.begin(), data.end());
    return request(m);
  }
  std::vector<std::uint8_t> set_epr(std::uint8_t instance, std::uint16_t ms) {
    return set(instance, 9, {static_cast<std::uint8_t>(ms), static_cast<std::uint8_t>(ms >> 8)});
  }
  std::vector<std::uint8_t> reset(std::uint8_t instance) { return request({0x05, 0x05, instance}); }
  // The path of Assembly `instance`'s data: 20 04 24 <instance> 30 03.
  static std::vector<std::uint8_t> assembly_path(std::uint16_t instance) {
    return {0x20, 0x04, 0x24, static_cast<std::uint8_t>(instance), 0x30, 0x03};
  }
  // An I/O message to the slave; its answer (`answer` of the slave's MAC)
  // heard within 5 ms, if any.
  std::optional<std::vector<std::uint8_t>> io(std::uint32_t to,
                                              const std::vector<std::uint8_t>& data,
                                              devicenet::Group1Message answer) {
    const std::size_t from = tester_.heard.size();
    tester_.send(TestNode::frame(to, data));
    world_.run_for(milliseconds(5));
    std::optional<std::vector<std::uint8_t>> out;
    const auto response_id = devicenet::group1_id(answer, mac(kSlaveMac));
    for (std::size_t i = from; i < tester_.heard.size(); ++i) {
      const can::CanFrame& f = tester_.heard[i].first;
      if (f.id == response_id) out.emplace(f.payload().begin(), f.payload().end());
    }
    return out;
  }
  // A poll command; the poll response heard, if any.
  std::optional<std::vector<std::uint8_t>> poll(const std::vector<std::uint8_t>& command) {
    return io(id(devicenet::Group2Message::kMasterIoPoll), command,
              devicenet::Group1Message::kSlavePollResponse);
  }
  // Change-of-state messages heard in [from, to).
  std::size_t cos_messages(TimePoint from, TimePoint to) const {
    std::size_t n = 0;
    for (const auto& [frame, at] : tester_.with_id(TestNode::cos_id())) {
      if (at >= from && at < to) ++n;
    }
    return n;
  }
  // The invariant: instance 4 produces exactly while it is Established.
  void expect_cos_follows_connection() {
    EXPECT_EQ(slave().cos_producing(), slave().cos_state() == sim::ConnectionState::kEstablished)
        << "instance 4 state " << static_cast<int>(slave().cos_state());
  }

  using Reply = std::vector<std::uint8_t>;
  static constexpr std::uint8_t kInstance2 = 2, kInstance4 = 4;

  sim::SimWorld world_;
  TestNode tester_;
  std::optional<sim::SimEdsSlave> slave_;
};

// An input or output assembly larger than one frame is no default: the
// connection carries nothing on that side, as attributes 7/8 say, rather than
// data cut to 8 bytes (inputs) or every poll taken as idle (outputs).
TEST_F(EdsSlaveByFrames, AnInputOverOneFrameIsNoDefaultAssembly) {
  start(io_block_with_long_input());
  EXPECT_EQ(slave().poll_input_assembly(), 0u);
  EXPECT_EQ(slave().cos_input_assembly(), 0u);
  EXPECT_EQ(slave().poll_output_assembly(), kOutputs);
  ASSERT_EQ(allocate(0x03), (Reply{0xCB, 0x00}));
  EXPECT_EQ(slave().connections().poll_connection().produced_assembly, 0u);
  EXPECT_EQ(get(kInstance2, 7), (Reply{0x8E, 0x00, 0x00}));  // produced size 0
  EXPECT_EQ(get(kInstance2, 13), (Reply{0x8E, 0x00}));       // no produced path
  EXPECT_EQ(get(kInstance2, 8), (Reply{0x8E, 0x02, 0x00}));  // the output's 2 bytes
  ASSERT_EQ(set_epr(kInstance2, 100), (Reply{0x90, 100, 0}));
  // The poll is applied and answered with what attribute 7 says: nothing.
  EXPECT_EQ(poll({0x3C, 0x00}), Reply{});
  EXPECT_EQ(param(4), 0x3C);
  // A path to the long input is refused as the default was.
  EXPECT_EQ(allocate(0x10), (Reply{0xCB, 0x00}));
  EXPECT_EQ(set(kInstance4, 14, assembly_path(kInputs)), (Reply{0x94, 0x09, 0xFF}));
}

TEST_F(EdsSlaveByFrames, AnOutputOverOneFrameIsNoDefaultAssembly) {
  start(io_block_with_long_output());
  EXPECT_EQ(slave().poll_input_assembly(), kInputs);
  EXPECT_EQ(slave().poll_output_assembly(), 0u);
  ASSERT_EQ(allocate(0x03), (Reply{0xCB, 0x00}));
  EXPECT_EQ(get(kInstance2, 8), (Reply{0x8E, 0x00, 0x00}));  // consumed size 0
  ASSERT_EQ(set_epr(kInstance2, 100), (Reply{0x90, 100, 0}));
  // A connection that consumes nothing has no idle condition: an empty poll
  // command is applied, a longer one ignored (oversize).
  EXPECT_EQ(poll({}), (Reply{0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(slave().counters().polls_applied, 1u);
  EXPECT_EQ(slave().counters().polls_idle, 0u);
  EXPECT_EQ(poll({0x01, 0x02}), std::nullopt);
  EXPECT_EQ(slave().counters().polls_oversize, 1u);
}

// A consumed path names an output assembly: the inputs' parameters (read
// only, the device's own) are no poll command's to overwrite.
TEST_F(EdsSlaveByFrames, AConsumedPathNamesAnOutputAssemblyOnly) {
  start();
  ASSERT_EQ(allocate(0x13), (Reply{0xCB, 0x00}));
  EXPECT_EQ(set(kInstance2, 16, assembly_path(kInputs)), (Reply{0x94, 0x09, 0xFF}));
  EXPECT_EQ(slave().connections().poll_connection().consumed_assembly, kOutputs);
  EXPECT_EQ(set(kInstance2, 16, assembly_path(kOutputs)), (Reply{0x90}));
  // Either assembly may be produced (an echo of the outputs).
  EXPECT_EQ(set(kInstance2, 14, assembly_path(kOutputs)), (Reply{0x90}));
  EXPECT_EQ(set(kInstance2, 14, assembly_path(kInputs)), (Reply{0x90}));
  // The change-of-state connection consumes acknowledgments, no data: its
  // consumed path is not settable, whatever it names.
  EXPECT_EQ(set(kInstance4, 16, assembly_path(kOutputs)), (Reply{0x94, 0x0E, 0xFF}));
  EXPECT_EQ(set(kInstance4, 16, assembly_path(kInputs)), (Reply{0x94, 0x0E, 0xFF}));
  EXPECT_EQ(get(kInstance4, 15), (Reply{0x8E, 0x00}));
}

// The valve manifold's bit-strobe connection (instance 3): allocated with
// 0x04, its produced path the StrobeInfo input (Assembly 102, the status
// byte), its consumed size the command's 8 bytes, its IDs Group 1 message 14
// and the owning master's Group 2 message 0. Established by its EPR, each
// command of its master is answered with the status; a command of another
// master is not; its watchdog times it out and then nothing is answered.
TEST_F(EdsSlaveByFrames, TheBitStrobeConnectionAnswersItsMastersCommands) {
  start(test::example_eds(test::kValveManifoldEds));
  constexpr std::uint8_t kInstance3 = 3;
  EXPECT_EQ(slave().strobe_input_assembly(), 102u);
  ASSERT_EQ(allocate(0x05), (Reply{0xCB, 0x00}));
  EXPECT_EQ(slave().connections().allocation_choice(), 0x05);
  EXPECT_EQ(get(kInstance3, 7), (Reply{0x8E, 0x01, 0x00}));
  EXPECT_EQ(get(kInstance3, 8), (Reply{0x8E, 0x08, 0x00}));
  EXPECT_EQ(get(kInstance3, 4), (Reply{0x8E, 0x85, 0x03}));  // 0x380 + 5
  EXPECT_EQ(get(kInstance3, 5), (Reply{0x8E, 0x00, 0x04}));  // 0x400 + (0 << 3)
  EXPECT_EQ(get(kInstance3, 14), (Reply{0x8E, 0x20, 0x04, 0x24, 0x66, 0x30, 0x03}));
  EXPECT_EQ(set(kInstance3, 16, assembly_path(102)), (Reply{0x94, 0x0E, 0xFF}));
  // Input1 (Assembly 101) is the poll connection's only ([IO_Info] mask 1).
  EXPECT_EQ(set(kInstance3, 14, assembly_path(101)), (Reply{0x94, 0x09, 0xFF}));
  EXPECT_EQ(set(kInstance3, 14, assembly_path(102)), (Reply{0x90}));

  const auto strobe = [&](unsigned master) {
    return io(devicenet::group2_id(mac(master), devicenet::Group2Message::kMasterBitStrobeCommand),
              {0x20, 0, 0, 0, 0, 0, 0, 0},  // bit 5: this device's
              devicenet::Group1Message::kSlaveBitStrobeResponse);
  };
  // Configuring: not answered.
  EXPECT_EQ(strobe(kMasterMac), std::nullopt);
  ASSERT_EQ(set_epr(kInstance3, 100), (Reply{0x90, 100, 0}));
  EXPECT_EQ(slave().strobe_state(), sim::ConnectionState::kEstablished);
  ASSERT_TRUE(slave().objects().set_assembly_data(102, Bytes(Reply{0x03})));
  EXPECT_EQ(strobe(kMasterMac), Reply{0x03});
  EXPECT_TRUE(slave().strobe_counters().last_bit);
  // Another master's command is not for it.
  EXPECT_EQ(strobe(9), std::nullopt);
  EXPECT_EQ(slave().strobe_counters().commands, 1u);
  // Each command restarts the watchdog; without them it times out (4 x 100 ms).
  world_.run_for(milliseconds(300));
  EXPECT_EQ(strobe(kMasterMac), Reply{0x03});
  world_.run_for(milliseconds(350));
  EXPECT_EQ(slave().strobe_state(), sim::ConnectionState::kEstablished);
  world_.run_for(milliseconds(100));
  EXPECT_EQ(slave().strobe_state(), sim::ConnectionState::kTimedOut);
  EXPECT_EQ(strobe(kMasterMac), std::nullopt);
  EXPECT_EQ(slave().strobe_counters().responses, 2u);
  // Released with the explicit connection: the set is unowned.
  EXPECT_EQ(release(0x05), (Reply{0xCC}));
  EXPECT_EQ(slave().owner(), devicenet::MacId::kNone);
}

// Acknowledge suppression alone names no connection: refused in Release as in
// Allocate, and the connection it qualifies stays.
TEST_F(EdsSlaveByFrames, ReleaseOfAcknowledgeSuppressionAloneIsRefused) {
  start();
  ASSERT_EQ(allocate(0x51), (Reply{0xCB, 0x00}));
  EXPECT_EQ(release(0x40), (Reply{0x94, 0x09, 0x02}));
  EXPECT_EQ(slave().connections().allocation_choice(), 0x51);
  EXPECT_EQ(slave().cos_state(), sim::ConnectionState::kConfiguring);
  EXPECT_EQ(release(0x50), (Reply{0xCC}));
  EXPECT_EQ(slave().connections().allocation_choice(), 0x01);
  EXPECT_EQ(slave().cos_state(), sim::ConnectionState::kNonExistent);
}

// Release is idle for the assembly the connection consumed: the one its
// consumed path named, not the EDS's default output.
TEST_F(EdsSlaveByFrames, ReleaseAppliesTheIdleActionToTheAssemblyThePathNamed) {
  start(io_block_with_two_outputs());
  set_param(9, {0x42});  // Output idle value
  set_param(4, {0x55});  // the default output's parameter, not consumed here
  ASSERT_EQ(allocate(0x03), (Reply{0xCB, 0x00}));
  ASSERT_EQ(set(kInstance2, 16, assembly_path(kOutputs2)), (Reply{0x90}));
  ASSERT_EQ(set_epr(kInstance2, 100), (Reply{0x90, 100, 0}));
  ASSERT_TRUE(poll({0x20, 0x00}).has_value());
  ASSERT_EQ(param(1), 0x20);
  EXPECT_EQ(release(0x02), (Reply{0xCC}));
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kNonExistent);
  EXPECT_EQ(param(1), 0x42);  // Output idle value, from the first byte
  EXPECT_EQ(param(4), 0x55);
}

// The fault action too, after the watchdog's Auto Delete has deleted it.
TEST_F(EdsSlaveByFrames, AutoDeleteAppliesTheFaultActionToTheAssemblyThePathNamed) {
  start(io_block_with_two_outputs());
  set_param(7, {0x24});  // Output fault value
  set_param(4, {0x55});
  ASSERT_EQ(allocate(0x03), (Reply{0xCB, 0x00}));
  ASSERT_EQ(set(kInstance2, 16, assembly_path(kOutputs2)), (Reply{0x90}));
  ASSERT_EQ(set(kInstance2, 12, {0x01}), (Reply{0x90}));  // Auto Delete
  ASSERT_EQ(set_epr(kInstance2, 100), (Reply{0x90, 100, 0}));
  ASSERT_TRUE(poll({0x20, 0x00}).has_value());
  world_.run_for(milliseconds(450));
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kNonExistent);
  EXPECT_EQ(param(1), 0x24);
  EXPECT_EQ(param(4), 0x55);
}

// Instance 4 produces exactly while it is Established: on through a watchdog
// with Auto Reset, again after a Connection Reset out of Timed Out, at the
// rate last set.
TEST_F(EdsSlaveByFrames, TheChangeOfStateConnectionGoesOnProducingThroughAutoReset) {
  start();
  ASSERT_EQ(allocate(0x11), (Reply{0xCB, 0x00}));
  ASSERT_EQ(set(kInstance4, 12, {0x02}), (Reply{0x90}));  // Auto Reset
  ASSERT_EQ(set_epr(kInstance4, 100), (Reply{0x90, 100, 0}));
  expect_cos_follows_connection();
  // No acknowledgment: the watchdog (4 x 100 ms) expires again and again.
  const TimePoint t = world_.now();
  world_.run_for(milliseconds(1000));
  EXPECT_GE(slave().connections().watchdog_timeouts(), 2u);
  EXPECT_EQ(slave().cos_state(), sim::ConnectionState::kEstablished);
  expect_cos_follows_connection();
  EXPECT_GE(cos_messages(t + milliseconds(500), t + milliseconds(1000)), 4u);
}

TEST_F(EdsSlaveByFrames, AResetOutOfTimedOutProducesAgain) {
  start();
  ASSERT_EQ(allocate(0x11), (Reply{0xCB, 0x00}));
  ASSERT_EQ(set_epr(kInstance4, 100), (Reply{0x90, 100, 0}));
  world_.run_for(milliseconds(450));  // no acknowledgment: timed out (action 0)
  ASSERT_EQ(slave().cos_state(), sim::ConnectionState::kTimedOut);
  expect_cos_follows_connection();
  const TimePoint quiet = world_.now();
  world_.run_for(milliseconds(300));
  EXPECT_EQ(cos_messages(quiet, world_.now()), 0u);
  EXPECT_EQ(reset(kInstance4), (Reply{0x85}));
  EXPECT_EQ(slave().cos_state(), sim::ConnectionState::kEstablished);
  expect_cos_follows_connection();
  tester_.auto_ack = true;
  const TimePoint t = world_.now();
  world_.run_for(milliseconds(1000));
  EXPECT_GE(cos_messages(t, world_.now()), 9u);  // the heartbeat, every 100 ms
  EXPECT_EQ(slave().cos_state(), sim::ConnectionState::kEstablished);
  EXPECT_TRUE(slave().objects().ack_handler().cos_acknowledged);
}

TEST_F(EdsSlaveByFrames, ANewRateOfAnEstablishedConnectionIsItsNewHeartbeat) {
  start();
  ASSERT_EQ(allocate(0x61), (Reply{0xCB, 0x00}));  // cyclic, no acknowledgment
  ASSERT_EQ(set_epr(kInstance4, 1000), (Reply{0x90, 0xE8, 0x03}));
  world_.run_for(milliseconds(1500));
  EXPECT_EQ(cos_messages(world_.now() - milliseconds(1500), world_.now()), 1u);
  ASSERT_EQ(set_epr(kInstance4, 100), (Reply{0x90, 100, 0}));
  expect_cos_follows_connection();
  const TimePoint t = world_.now();
  world_.run_for(milliseconds(1000));
  EXPECT_GE(cos_messages(t, world_.now()), 9u);
  const auto& c = slave().connections().cos_connection();
  EXPECT_EQ(c.expected_packet_rate_ms, 100);
}

}  // namespace
}  // namespace dnbridge::test
