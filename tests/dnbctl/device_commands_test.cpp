// dnbctl with a device described by its EDS file (profile "eds"), the real
// program as a child process against a bridge in this process: racks and
// list count it, show gives its inputs and outputs as the EDS's fields,
// outputs commands it by field or as bytes and reports a refusal with the
// bridge's reason, a pump is not commanded as a device, and assembly reads
// the member lists.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/daemon.hpp"
#include "adapters/daemon/log_sink.hpp"
#include "adapters/daemon/simulated_backends.hpp"
#include "adapters/dds/fields.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "subprocess.hpp"
#include "test_domain.hpp"

namespace dnbridge::dnbctl {
namespace {

using testing::RunResult;
using testing::test_domain;

constexpr auto kReady = std::chrono::seconds(10);
constexpr unsigned kDevice = 20;

class DnbctlDevices : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto config = daemon::parse_config(
        "rack = \"eds-rack\"\n"
        "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
        "[[port.node]]\nmac = 1\nname = \"pump-1\"\n"
        "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
        "eds = \"dnbridge-example-io-block.eds\"\n"
        // What one dnbctl run commanded stays applied when it exits, for the
        // test to see (and for the next run to find).
        "no_commander = \"hold\"\n"
        "safe_state_parameters = [ { name = \"Output fault action\", value = 0 },\n"
        "               { name = \"Output fault value\", value = 0 },\n"
        "               { name = \"Output idle action\", value = 0 },\n"
        "               { name = \"Output idle value\", value = 0 } ]\n",
        "dnbctl-devices.toml", DNBRIDGE_EDS_DIR);
    config.domain_id = test_domain();
    log_ = std::make_unique<daemon::StderrLogSink>(LogLevel::kWarn);
    bridge_ = std::make_unique<daemon::Daemon>(std::move(config), *log_,
                                               daemon::simulated_backend_factory(*log_));
    bridge_->start();
  }

  static void TearDownTestSuite() {
    if (bridge_) bridge_->stop();
    bridge_.reset();
    log_.reset();
  }

  // Until the device's DeviceState satisfies `ok`; false after kReady.
  template <class Pred>
  bool wait_device(Pred ok) {
    const auto deadline = std::chrono::steady_clock::now() + kReady;
    for (;;) {
      if (auto samples = devices_.take()) {
        for (auto& s : *samples) {
          if (s.valid_data() && s->mac == kDevice) std::swap(*latest_, s.data());
        }
      }
      if (latest_->mac == kDevice && ok(*latest_)) return true;
      if (std::chrono::steady_clock::now() >= deadline) return false;
      (void)waitset_.wait(milliseconds(100));
    }
  }

  void SetUp() override {
    ASSERT_TRUE(bridge_);
    (void)devices_.set_status_mask(DDS_DATA_AVAILABLE_STATUS);
    waitset_.attach(devices_, 1);
    ASSERT_TRUE(wait_device([](const dnbridge_DeviceState& s) {
      return s.online && s.inputs_valid;
    })) << "the device did not come online";
  }

  static RunResult dnbctl(std::vector<std::string> args) {
    args.insert(args.begin(), {"--domain", std::to_string(test_domain())});
    return testing::run(DNBCTL_PATH, args);
  }

  static inline std::unique_ptr<daemon::StderrLogSink> log_;
  static inline std::unique_ptr<daemon::Daemon> bridge_;

  dds::Participant participant_{static_cast<dds_domainid_t>(test_domain()),
                                dds::Participant::ClientName{"dnbctl device observer"}};
  dds::Topic<dnbridge_DeviceState> topic_{participant_};
  dds::Reader<dnbridge_DeviceState> devices_{participant_, topic_, dds::state_reader_qos()};
  dds::WaitSet waitset_{participant_};
  dds::Owned<dnbridge_DeviceState> latest_;
};

TEST_F(DnbctlDevices, RacksAndListCountTheDevice) {
  const auto r = dnbctl({"racks"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("not every configured node"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("eds-rack  A     20   io-1    idle"), std::string::npos) << r.out;
  const auto list = dnbctl({"list", "--nodes"});
  ASSERT_EQ(list.exit_code, 0) << list.err;
  EXPECT_NE(list.out.find("Example IO block 8DI/8DO/1AI"), std::string::npos) << list.out;
}

TEST_F(DnbctlDevices, ShowGivesTheDevicesDataAsItsFields) {
  const auto r = dnbctl({"show", "io-1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("product (EDS)             Example IO block 8DI/8DO/1AI"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("inputs                    [00 00 00 00] Digital inputs = 0; Module "
                       "status = 0; Analog input 1 = 0 mV"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("Param9 Output idle value = 0"), std::string::npos) << r.out;
}

TEST_F(DnbctlDevices, OutputsCommandsTheDeviceByFieldOrBytesAndReportsARefusal) {
  auto r = dnbctl({"outputs", "20", "Digital outputs=0x81", "--issuer", "bench"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("eds-rack/A/20 (io-1): applied: [81 00]; commanded by \"bench\""),
            std::string::npos)
      << r.out;
  EXPECT_TRUE(wait_device([](const dnbridge_DeviceState& s) {
    const auto out = dds::view(s.outputs);
    return !s.outputs_idle && out.size() == 2 && out[0] == 0x81;
  }));

  r = dnbctl({"outputs", "io-1", "--bytes", "0300", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"applied\": true"), std::string::npos) << r.out;

  // By its parameter number: the echo is found by it too.
  r = dnbctl({"outputs", "20", "Param4=5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("applied: [05 00]"), std::string::npos) << r.out;

  r = dnbctl({"outputs", "20", "Digital outputs=300"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("not applied: refused by the bridge: from dnbctl "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("Digital outputs: 300 is outside 0..255"), std::string::npos) << r.err;

  // Usage errors: nothing is sent.
  r = dnbctl({"pump", "20", "on"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("is a device of profile \"eds\", not a pump"), std::string::npos) << r.err;
  r = dnbctl({"outputs", "1", "--bytes", "0100"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("is a pump (a CDN127)"), std::string::npos) << r.err;
  r = dnbctl({"outputs", "20", "Digital outputs"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("is not NAME=VALUE"), std::string::npos) << r.err;
  r = dnbctl({"outputs", "20", "Digital outputs=1", "--bytes", "0100"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("not both"), std::string::npos) << r.err;
}

TEST_F(DnbctlDevices, ParamReadsAndWritesByNameUnderTheGatewayPolicy) {
  const std::string eds = std::string(DNBRIDGE_EDS_DIR) + "/dnbridge-example-io-block.eds";
  // Read by name: the value in its type and units, decoded from the EDS.
  auto r = dnbctl({"param", "io-1", "Analog input 1", "--eds", eds});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "eds-rack/A/20: Param2 \"Analog input 1\" = 0 mV (INT, 00 00)\n");

  // Written and read back: a parameter the bridge does not manage.
  r = dnbctl({"param", "20", "Input filter", "12", "--eds", eds, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"written\": true"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"holds_written\": true"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"value\": 12"), std::string::npos) << r.out;
  r = dnbctl({"param", "20", "Param1", "--eds", eds});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("= 12 ms (UINT, 0C 00)"), std::string::npos) << r.out;

  // One of its safe state: the gateway refuses it, naming the key.
  r = dnbctl({"param", "io-1", "Output idle value", "1", "--eds", eds});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("allow_managed_attribute_writes = true in [explicit_policy] allows it"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("Param9 \"Output idle value\" (class 0x0F instance 0x09 attribute 0x01)"),
            std::string::npos)
      << r.err;

  // Another device's EDS: not written to this one.
  r = dnbctl({"param", "io-1", "Low pressure limit", "300", "--eds",
              std::string(DNBRIDGE_EDS_DIR) + "/dnbridge-example-valve-manifold.eds"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("is vendor 65001, product type 7, product code 1; "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(": not written"), std::string::npos) << r.err;

  // Checked against the EDS before anything is sent.
  r = dnbctl({"param", "io-1", "Input filter", "70000", "--eds", eds});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("70000 is outside the EDS's limits 0..100"), std::string::npos) << r.err;
  r = dnbctl({"param", "io-1", "Input filtr", "--eds", eds});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("(did you mean \"Input filter\"?)"), std::string::npos) << r.err;
  r = dnbctl({"param", "io-1", "Analog input 1", "1", "--eds", eds});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("is read only"), std::string::npos) << r.err;
}

TEST_F(DnbctlDevices, AssemblyShowsTheMemberLists) {
  auto r = dnbctl({"assembly", "io-1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("eds-rack/A/20 Assembly (class 0x04): revision 1, max instance 150\n"
                       "instance 100: 3 member(s), 32 bits\n"
                       "    1      8 bits  class 0x0F instance 0x03 attribute 0x01\n"
                       "    2      8 bits  class 0x0F instance 0x05 attribute 0x01\n"
                       "    3     16 bits  class 0x0F instance 0x02 attribute 0x01\n"
                       "instance 150: 2 member(s), 16 bits\n"
                       "    1      8 bits  class 0x0F instance 0x04 attribute 0x01\n"
                       "    2      8 bits  padding\n"),
            std::string::npos)
      << r.out;
  r = dnbctl({"assembly", "20", "150", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"padding\": true"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("\"instance\": 100"), std::string::npos) << r.out;
  // A device without attribute 2 (the CDN127) says so per instance.
  r = dnbctl({"assembly", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("instance 100: (member list not read: the device answered 0x14 "
                       "(attribute not supported))"),
            std::string::npos)
      << r.out;
  r = dnbctl({"assembly", "20", "7"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no assembly instance 7"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dnbridge::dnbctl
