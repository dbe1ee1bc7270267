// The master's traffic as Wireshark's DeviceNet dissector decodes it: a short
// simulated rack run (two CDN127s, master MAC 0, virtual time) is captured to
// a pcap file and read back with tshark. This checks the wire against an
// independent decoder, not against our own codecs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "adapters/sim/bus/pcap_writer.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/profiles/cdn127/objects.hpp"
#include "integration/rack_fixture.hpp"

namespace dnbridge::test {
namespace {

namespace cdn127 = profiles::cdn127;

constexpr unsigned kMaster = 0;
constexpr unsigned kPumpA = 3;
constexpr unsigned kPumpB = 17;
constexpr std::uint32_t kMasterSerial = 0xDB000001;

// One frame as tshark decoded it. Fields the dissector did not fill are empty.
struct WireRow {
  unsigned number = 0;
  double time = 0;  // seconds since the capture's start (its epoch is 0)
  std::uint32_t can_id = 0;
  unsigned len = 0;
  std::optional<unsigned> group1_id;
  std::optional<unsigned> group2_id;
  std::optional<unsigned> mac;  // "Source MAC ID" (tshark's name, also for destination MACs)
  std::optional<unsigned> dup_rr;
  std::optional<unsigned> dup_port;
  std::optional<unsigned> dup_vendor;
  std::optional<std::uint32_t> dup_serial;
  std::vector<std::uint8_t> data;  // devicenet.data: the body the dissector left undecoded
};

// The fields asked of tshark, in WireRow's order (`tshark -G fields | grep devicenet`).
const char* const kFields[] = {
    "frame.number",
    "frame.time_epoch",
    "can.id",
    "can.len",
    "devicenet.grp_msg1.id",
    "devicenet.grp_msg2.id",
    "devicenet.src_mac_id",
    "devicenet.dup_mac_id.rr",
    "devicenet.dup_mac_id.physical_port_number",
    "devicenet.dup_mac_id.vendor",
    "devicenet.dup_mac_id.serial_number",
    "devicenet.data",
};

std::optional<unsigned long> number(const std::string& s) {
  if (s.empty()) return std::nullopt;
  return std::stoul(s, nullptr, 0);  // tshark prints some fields in hex ("0x003b")
}

std::vector<std::uint8_t> hex(const std::string& s) {
  std::vector<std::uint8_t> out;
  if (s == "<MISSING>") return out;  // how tshark prints an empty byte field (zero-length poll)
  for (std::size_t i = 0; i + 1 < s.size(); i += 2)
    out.push_back(static_cast<std::uint8_t>(std::stoul(s.substr(i, 2), nullptr, 16)));
  return out;
}

std::vector<std::string> split_tabs(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, '\t')) out.push_back(cell);
  if (!line.empty() && line.back() == '\t') out.emplace_back();
  return out;
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string hex_string(const std::vector<std::uint8_t>& bytes) {
  std::string s;
  char buf[4];
  for (auto b : bytes) {
    std::snprintf(buf, sizeof buf, "%02x ", b);
    s += buf;
  }
  return s;
}

class Wire : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const auto dir = std::filesystem::temp_directory_path();
    pcap_ = dir / ("dnbridge_wire_" + std::string(info->name()) + "_" + std::to_string(::getpid()) +
                   ".pcap");
    tshark_err_ = pcap_;
    tshark_err_.replace_extension(".stderr");
    ASSERT_NO_FATAL_FAILURE(run_rack());
    ASSERT_NO_FATAL_FAILURE(decode());
  }

  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove(tshark_err_, ignored);
    if (HasFailure()) {
      std::printf("capture kept for inspection: %s\n", pcap_.c_str());
    } else {
      std::filesystem::remove(pcap_, ignored);
    }
  }

  // Start, wait online, command an output, read a Device Supervisor string
  // (a fragmented response), stop; all captured.
  void run_rack() {
    rack_ = std::make_unique<sim::SimRack>(rack_config({kPumpA, kPumpB}, kMaster));
    rack_->observe(events_);
    capture_ = std::make_unique<sim::BusCapture>(rack_->world().bus(),
                                                 sim::PcapWriter(pcap_.string(), rack_->now()));
    rack_->start();
    ASSERT_TRUE(rack_->world().run_until([&] { return rack_->all_online(); }, seconds(10)));

    cdn127::PumpOutputs out;
    out.pump_on = true;
    ASSERT_TRUE(rack_->pumps().command(mac(kPumpA), out, rack_->now()).ok());
    rack_->world().run_for(milliseconds(250));

    devicenet::RequestMessage get;
    get.service = cip::code(cip::Service::kGetAttributeSingle);
    get.class_id = cdn127::class_id::kDeviceSupervisor;
    get.instance_id = 1;
    get.attribute = cdn127::supervisor_attr::kManufacturerName;
    auto id = rack_->scanner().request_explicit(mac(kPumpB), get, rack_->now());
    ASSERT_TRUE(id.ok()) << id.error().message();
    ASSERT_TRUE(
        rack_->world().run_until([&] { return events_.result(*id) != nullptr; }, seconds(2)));
    const auto& r = events_.result(*id)->result;
    ASSERT_TRUE(r.ok()) << r.error.message();
    supervisor_name_ = std::string(r.data.view().begin(), r.data.view().end());

    rack_->scanner().stop(rack_->now());
    ASSERT_TRUE(rack_->world().run_until([&] { return rack_->scanner().stopped(); }, seconds(5)));
    rack_->world().run_for(milliseconds(100));
    ASSERT_FALSE(rack_->world().bus().busy());
    stats_ = rack_->world().bus().stats();
    captured_ = capture_->frames();
    ASSERT_TRUE(capture_->close()) << capture_->writer().error().message();
  }

  void decode() {
    const std::string tshark = DNBRIDGE_TSHARK;
    ASSERT_FALSE(tshark.empty())
        << "tshark was not found when the build was configured; install it (bash .ci/deps, which "
           "runs apt-get install tshark) and configure again";
    ASSERT_EQ(::access(tshark.c_str(), X_OK), 0)
        << "tshark not executable at " << tshark
        << ": install it (bash .ci/deps) and configure again";

    std::string cmd = "'" + tshark + "' -n -r '" + pcap_.string() +
                      "' -d can.subdissector,devicenet -T fields -E separator=/t -E occurrence=f";
    for (const char* f : kFields) cmd += std::string(" -e ") + f;
    cmd += " 2>'" + tshark_err_.string() + "'";
    std::FILE* pipe = ::popen(cmd.c_str(), "r");
    ASSERT_NE(pipe, nullptr) << "cannot run: " << cmd;
    std::string out;
    char buf[4096];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
    const int status = ::pclose(pipe);
    ASSERT_EQ(status, 0) << "tshark failed (" << status << "): " << cmd << "\n"
                         << read_text(tshark_err_);

    std::istringstream lines(out);
    std::string line;
    while (std::getline(lines, line)) {
      const auto c = split_tabs(line);
      ASSERT_EQ(c.size(), std::size(kFields)) << "unexpected tshark line: " << line;
      WireRow r;
      try {
        parse(c, r);
      } catch (const std::exception& e) {
        FAIL() << "cannot parse tshark line (" << e.what() << "): " << line;
      }
      rows_.push_back(std::move(r));
    }
    ASSERT_FALSE(rows_.empty()) << "tshark decoded no frame: " << read_text(tshark_err_);
  }

  static void parse(const std::vector<std::string>& c, WireRow& r) {
    r.number = static_cast<unsigned>(std::stoul(c[0]));
    r.time = std::stod(c[1]);
    r.can_id = static_cast<std::uint32_t>(std::stoul(c[2], nullptr, 0));
    r.len = static_cast<unsigned>(std::stoul(c[3]));
    auto u = [](const std::string& s) -> std::optional<unsigned> {
      if (auto v = number(s)) return static_cast<unsigned>(*v);
      return std::nullopt;
    };
    r.group1_id = u(c[4]);
    r.group2_id = u(c[5]);
    r.mac = u(c[6]);
    r.dup_rr = u(c[7]);
    r.dup_port = u(c[8]);
    r.dup_vendor = u(c[9]);
    if (auto v = number(c[10])) r.dup_serial = static_cast<std::uint32_t>(*v);
    r.data = hex(c[11]);
  }

  std::vector<const WireRow*> group2(unsigned message, unsigned m) const {
    std::vector<const WireRow*> out;
    for (const auto& r : rows_) {
      if (r.group2_id == message && r.mac == m) out.push_back(&r);
    }
    return out;
  }
  std::vector<const WireRow*> group1(unsigned message, unsigned m) const {
    std::vector<const WireRow*> out;
    for (const auto& r : rows_) {
      if (r.group1_id == message && r.mac == m) out.push_back(&r);
    }
    return out;
  }
  const devicenet::Node& node(unsigned m) { return *rack_->scanner().node(mac(m)); }

  std::filesystem::path pcap_;
  std::filesystem::path tshark_err_;
  std::unique_ptr<sim::SimRack> rack_;
  std::unique_ptr<sim::BusCapture> capture_;
  EventRecorder events_;
  sim::BusStats stats_;
  std::uint64_t captured_ = 0;
  std::string supervisor_name_;
  std::vector<WireRow> rows_;
};

TEST_F(Wire, DuplicateMacChecksCarryVendorAndSerialNumber) {
  struct Expected {
    unsigned mac;
    unsigned vendor;
    std::uint32_t serial;
  };
  const Expected expected[] = {
      {kMaster, 59, kMasterSerial},
      {kPumpA, cdn127::kVendorId, sim::default_slave_options(mac(kPumpA)).serial_number},
      {kPumpB, cdn127::kVendorId, sim::default_slave_options(mac(kPumpB)).serial_number},
  };
  for (const auto& e : expected) {
    SCOPED_TRACE("MAC " + std::to_string(e.mac));
    const auto checks = group2(7, e.mac);
    // Two requests one second apart at power-up, then silence: nobody
    // claimed the MAC (bridge/PROTOCOL.md §6).
    ASSERT_EQ(checks.size(), 2u);
    for (const WireRow* r : checks) {
      EXPECT_EQ(r->can_id, 0x407u + (e.mac << 3));
      EXPECT_EQ(r->len, 7u);
      EXPECT_EQ(r->dup_rr, 0u) << "a request, not a response";
      EXPECT_EQ(r->dup_port, 0u);
      EXPECT_EQ(r->dup_vendor, e.vendor);
      EXPECT_EQ(r->dup_serial, e.serial);
    }
    // The capture's clock: the first check as the rack starts, the second 1 s later.
    EXPECT_LT(checks[0]->time, 0.001);
    EXPECT_NEAR(checks[1]->time - checks[0]->time, 1.0, 0.001);
  }
}

TEST_F(Wire, Group2MessagesCarryTheSlaveMac) {
  const double master_checked = group2(7, kMaster).back()->time;
  for (unsigned m : {kPumpA, kPumpB}) {
    SCOPED_TRACE("MAC " + std::to_string(m));
    // Allocate (G2 message 6 to the slave): [hdr: MAC 0][4B][class 3][instance 1]
    // [choice][allocator MAC 0], after the master's own check: the explicit
    // connection alone first, the poll connection once the configuration is
    // in place; Release of both at the stop.
    const auto allocs = group2(6, m);
    ASSERT_EQ(allocs.size(), 3u);  // Allocate explicit, Allocate poll, Release at the stop
    for (const auto& [alloc, choice] : {std::pair{allocs[0], 0x01}, std::pair{allocs[1], 0x02}}) {
      SCOPED_TRACE(hex_string(alloc->data));
      EXPECT_EQ(alloc->can_id, 0x406u + (m << 3));
      ASSERT_EQ(alloc->data.size(), 6u);
      EXPECT_EQ(alloc->data[0] & 0xBF, kMaster) << "header: no Frag, master MAC";
      EXPECT_EQ(alloc->data[1], 0x4B);
      EXPECT_EQ(alloc->data[2], 0x03);
      EXPECT_EQ(alloc->data[3], 0x01);
      EXPECT_EQ(alloc->data[4], choice);
      EXPECT_EQ(alloc->data[5], kMaster);
      EXPECT_GT(alloc->time, master_checked + 0.9);
    }
    EXPECT_LT(allocs[0]->time, allocs[1]->time);
    // Release at the end: [hdr][4C][03][01][explicit + poll].
    const WireRow& release = *allocs.back();
    ASSERT_EQ(release.data.size(), 5u) << hex_string(release.data);
    EXPECT_EQ(release.data[1], 0x4C);
    EXPECT_EQ(release.data[4], 0x03);

    // Slave responses (message 3, source MAC): the Allocate's success first.
    const auto responses = group2(3, m);
    ASSERT_FALSE(responses.empty());
    EXPECT_EQ(responses.front()->can_id, 0x403u + (m << 3));
    ASSERT_GE(responses.front()->data.size(), 3u);
    EXPECT_EQ(responses.front()->data[1], 0xCB);
    EXPECT_EQ(responses.back()->data, (std::vector<std::uint8_t>{release.data[0], 0xCC}));

    // Explicit requests (message 4) all carry the master's MAC in their header.
    const auto requests = group2(4, m);
    ASSERT_FALSE(requests.empty());
    for (const WireRow* r : requests) {
      EXPECT_EQ(r->can_id, 0x404u + (m << 3));
      ASSERT_FALSE(r->data.empty());
      EXPECT_EQ(r->data[0] & 0x3F, kMaster) << "frame " << r->number;
    }
    // Each request the master counted starts one message on the wire: the
    // Allocate and Release on message 6, the others on message 4 as an
    // unfragmented frame or a first fragment (the rest of message 4 is further
    // fragments and acks of the slave's fragments).
    const auto starts = std::count_if(requests.begin(), requests.end(), [](const WireRow* r) {
      return !(r->data[0] & 0x80) || (r->data.size() >= 2 && r->data[1] == 0x00);
    });
    EXPECT_EQ(static_cast<std::uint64_t>(starts) + allocs.size(),
              node(m).explicit_counters().requests);

    // Poll commands (message 5), as many as the master counted.
    const auto polls = group2(5, m);
    EXPECT_EQ(polls.size(), node(m).counters().polls);
    for (const WireRow* r : polls) EXPECT_EQ(r->can_id, 0x405u + (m << 3));
    // The orderly stop ends with one idle (zero-length) poll.
    ASSERT_FALSE(polls.empty());
    EXPECT_EQ(polls.back()->len, 0u);
  }
  // Nothing in Group 2 but the master's own duplicate MAC check names MAC 0
  // or a MAC outside the scan list.
  for (const auto& r : rows_) {
    if (!r.group2_id || r.group2_id == 7u) continue;
    EXPECT_TRUE(r.mac == kPumpA || r.mac == kPumpB) << "frame " << r.number << " id " << r.can_id;
  }
}

TEST_F(Wire, PollResponsesAreGroup1Message15FromEachSlave) {
  for (unsigned m : {kPumpA, kPumpB}) {
    SCOPED_TRACE("MAC " + std::to_string(m));
    const auto responses = group1(15, m);
    EXPECT_EQ(responses.size(), node(m).counters().responses);
    EXPECT_EQ(responses.size(), group2(5, m).size()) << "every poll answered";
    for (const WireRow* r : responses) EXPECT_EQ(r->can_id, 0x3C0u + m);
  }
  // The connection set allocated is explicit + poll: no other Group 1 message.
  for (const auto& r : rows_) {
    if (r.group1_id) {
      EXPECT_EQ(r.group1_id, 15u) << "frame " << r.number;
    }
  }
}

TEST_F(Wire, FragmentedSupervisorStringIsAcknowledgedFragmentByFragment) {
  ASSERT_EQ(supervisor_name_, std::string("\x0b") + "D.I.P. Inc.");
  // The slave's fragments (message 3 from pump B, Frag bit set) carrying the
  // response [8E][SHORT_STRING], each acked by the master on message 4 with
  // [hdr | Frag][C0 | count][00] (bridge/PROTOCOL.md §5).
  const auto from_slave = group2(3, kPumpB);
  auto first = std::find_if(from_slave.begin(), from_slave.end(), [](const WireRow* r) {
    return r->data.size() >= 4 && (r->data[0] & 0x80) && r->data[1] == 0x00 && r->data[2] == 0x8E &&
           r->data[3] == 0x0B;
  });
  ASSERT_NE(first, from_slave.end()) << "no first fragment of the supervisor string";
  std::vector<std::uint8_t> message;
  std::vector<unsigned> types;
  for (auto it = first; it != from_slave.end(); ++it) {
    const WireRow& frag = **it;
    ASSERT_GE(frag.data.size(), 2u);
    ASSERT_TRUE(frag.data[0] & 0x80) << "frame " << frag.number << ": " << hex_string(frag.data);
    const unsigned count = static_cast<unsigned>(types.size());
    types.push_back(frag.data[1] >> 6);
    EXPECT_EQ(frag.data[1] & 0x3Fu, count) << "frame " << frag.number;
    message.insert(message.end(), frag.data.begin() + 2, frag.data.end());
    // The very next frame on the wire is the master's ack.
    ASSERT_LT(frag.number, rows_.size());
    const WireRow& ack = rows_[frag.number];  // frame numbers start at 1
    EXPECT_EQ(ack.group2_id, 4u);
    EXPECT_EQ(ack.mac, kPumpB);
    EXPECT_EQ(ack.data, (std::vector<std::uint8_t>{frag.data[0],
                                                   static_cast<std::uint8_t>(0xC0 | count), 0x00}))
        << "ack of frame " << frag.number;
    if (types.back() == 2) break;
  }
  // 13 bytes: first (type 0), middle (1) and last (2) fragment.
  EXPECT_EQ(types, (std::vector<unsigned>{0, 1, 2}));
  std::vector<std::uint8_t> expected{0x8E};
  expected.insert(expected.end(), supervisor_name_.begin(), supervisor_name_.end());
  EXPECT_EQ(message, expected);
}

TEST_F(Wire, FrameCountsMatchTheBusStatistics) {
  ASSERT_EQ(stats_.unacknowledged, 0u);
  ASSERT_EQ(stats_.aborted, 0u);
  EXPECT_EQ(rows_.size(), captured_);
  EXPECT_EQ(rows_.size(), stats_.transmitted);
  EXPECT_EQ(rows_.size(), stats_.delivered);
  std::map<std::uint32_t, std::uint64_t> per_id;
  for (const auto& r : rows_) ++per_id[r.can_id];
  for (const auto& [id, n] : per_id)
    EXPECT_EQ(n, rack_->world().bus().frames_with_id(id)) << "id " << id;
  // In wire order, numbered from 1, time never going back.
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    EXPECT_EQ(rows_[i].number, i + 1);
    if (i > 0) {
      EXPECT_GE(rows_[i].time, rows_[i - 1].time) << "frame " << rows_[i].number;
    }
  }
}

}  // namespace
}  // namespace dnbridge::test
