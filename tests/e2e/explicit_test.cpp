// Explicit messaging through DDS, in the scanner transaction model: Gets of
// Identity and Device Supervisor strings (fragmented on the wire), a repeated
// request answered again and not executed again, and every transaction status
// that can be provoked against the simulated rack.
//
// Status 12 (response too large) is not provoked: it needs a device whose
// response is over 512 bytes (devicenet::kMaxExplicitMessage), and no
// attribute of the CDN127, real or simulated, comes near that (the longest,
// Device Supervisor Exception Detail, is a few tens of bytes).
#include <algorithm>
#include <atomic>
#include <memory>
#include <vector>

#include "bridge/devicenet/wire/identifier.hpp"
#include "bridge/profiles/cdn127/objects.hpp"
#include "bridge_fixture.hpp"

namespace dnbridge::e2e {
namespace {

namespace cdn127 = profiles::cdn127;
using devicenet::group2_id;
using devicenet::Group2Message;

constexpr std::uint8_t kSuccess = 1, kInProgress = 2, kNotInScanList = 3, kSlaveOffline = 4,
                       kPortOffline = 5, kTxidUnknown = 6, kInvalidCommand = 8, kOutOfBuffers = 9,
                       kOtherTransaction = 10, kCouldNotConnect = 11, kInvalidPort = 13,
                       kInvalidSize = 14, kConnectionBusy = 15;
static_assert(kSuccess == dnbridge_STATUS_SUCCESS &&
              kConnectionBusy == dnbridge_STATUS_CONNECTION_BUSY);

devicenet::MacId mac_id(unsigned mac) { return *devicenet::MacId::from(mac); }

// What crosses the simulated cable for node 1's explicit connection.
struct WireCount {
  std::atomic<unsigned> serial_number_requests{0};  // Get Identity attribute 6
  std::atomic<unsigned> response_fragments{0};      // fragmented explicit responses' frames
};

Request get(std::uint32_t txid, unsigned mac, std::uint16_t class_id, std::uint8_t attribute) {
  Request r;
  r.txid = txid;
  r.mac = static_cast<std::uint8_t>(mac);
  r.class_id = class_id;
  r.attribute = attribute;
  return r;
}

std::vector<std::uint8_t> short_string(std::string_view s) {
  std::vector<std::uint8_t> out{static_cast<std::uint8_t>(s.size())};
  out.insert(out.end(), s.begin(), s.end());
  return out;
}

TEST_F(ExplicitTest, GetsIdentityAndFragmentedDeviceSupervisorStringsThroughDds) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  auto wire = std::make_shared<WireCount>();
  on_port([wire](sim::SimBackend& b) {
    b.world().bus().set_tap([wire](const sim::WireFrame& w) {
      const auto& f = w.frame;
      if (f.id == group2_id(mac_id(1), Group2Message::kSlaveExplicitResponse) && f.len > 0 &&
          (f.data[0] & 0x80) != 0) {
        ++wire->response_fragments;
      }
    });
  });

  const auto sent = SteadyClock::now();
  ASSERT_NO_FATAL_FAILURE(
      send(get(1, 1, cdn127::class_id::kIdentity, cdn127::identity_attr::kProductName)));
  const auto name = reply(1);
  ASSERT_TRUE(name);
  report("explicit Get through DDS: request written -> reply", ms_since(sent));
  EXPECT_EQ(name->status, kSuccess) << name->message;
  EXPECT_EQ(name->general_status, 0);
  EXPECT_EQ(name->data, short_string("CDN127"));
  const unsigned fragments_of_name = wire->response_fragments;
  // [header][service][len] "CDN127": 9 bytes, more than one frame carries.
  EXPECT_GE(fragments_of_name, 2u);

  ASSERT_NO_FATAL_FAILURE(send(
      get(2, 1, cdn127::class_id::kDeviceSupervisor, cdn127::supervisor_attr::kManufacturerName)));
  const auto maker = reply(2);
  ASSERT_TRUE(maker);
  EXPECT_EQ(maker->status, kSuccess) << maker->message;
  EXPECT_EQ(maker->data, short_string("D.I.P. Inc."));
  // 14 bytes of message: three fragments.
  EXPECT_GE(wire->response_fragments - fragments_of_name, 3u);

  // An attribute the device does not have: the transaction completes with
  // the device's CIP error.
  ASSERT_NO_FATAL_FAILURE(send(get(3, 1, cdn127::class_id::kIdentity, 99)));
  const auto missing = reply(3);
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, kSuccess);
  EXPECT_EQ(missing->general_status, 0x14);  // attribute not supported
  EXPECT_TRUE(missing->data.empty());
}

TEST_F(ExplicitTest, ARequesterNameWithANulInsideIsRefused) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  // What a client in another language can send: this requester's name, a
  // NUL, and more. Read as a C string it is this requester's name; executed,
  // two such clients would take each other's transactions. Made here from
  // the serialized form of a request named with an X where the NUL goes.
  dds::Reader<dnbridge_ExplicitRequest> tap(supervisor_, request_topic_,
                                            dds::request_reader_qos(dds::rack_partitions(kRack)));
  dds::ReadCondition fresh(tap, DDS_NOT_READ_SAMPLE_STATE);
  dds::Owned<dnbridge_ExplicitRequest> r;
  dds::set_string(r->requester, requester_ + "Xtwin");
  r->txid = 77;
  r->command = dnbridge_COMMAND_EXECUTE;
  dds::set_string(r->rack, kRack);
  dds::set_string(r->port, kPort);
  r->mac = 1;
  r->service = 0x0E;
  r->class_id = 1;
  r->instance_id = 1;
  r->has_attribute = true;
  r->attribute_id = 1;
  ASSERT_TRUE(requests_.write(*r).ok());
  ASSERT_TRUE(dds::testing::wait_for(supervisor_, fresh));
  dds::testing::Serialized with_nul = dds::testing::take_serialized(tap);
  ASSERT_TRUE(dds::testing::put_nul(with_nul, "Xtwin"));
  ASSERT_EQ(dds::testing::write_serialized(requests_, std::move(with_nul)), DDS_RETCODE_OK);

  const auto refused = reply(77);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, dnbridge_STATUS_INVALID_COMMAND) << refused->message;
  EXPECT_NE(refused->message.find("NUL"), std::string::npos) << refused->message;
  EXPECT_TRUE(log_.contains(LogLevel::kWarn, "goes on past a NUL character"));
}

TEST_F(ExplicitTest, AnOversizedRequestIsDroppedUnansweredAndTheLargestServedOneIsAnswered) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  // A reply quotes its requester and may quote its port: a request of over
  // 2 KiB serialized is not answered, so that no reply can be that large.
  Request oversized = get(90, 1, cdn127::class_id::kIdentity, cdn127::identity_attr::kVendor);
  oversized.port = std::string(3000, 'p');
  ASSERT_NO_FATAL_FAILURE(send(oversized));
  // The largest request the bridge serves: 512 bytes of data, a port name of
  // 100 characters (no such port here).
  Request largest = get(91, 1, cdn127::class_id::kIdentity, cdn127::identity_attr::kVendor);
  largest.port = std::string(100, 'q');
  largest.data.assign(512, 0x55);
  ASSERT_NO_FATAL_FAILURE(send(largest));
  const auto answered = reply(91);
  ASSERT_TRUE(answered) << "the largest request the bridge serves was not answered";
  EXPECT_EQ(answered->status, kInvalidPort) << answered->message;
  // One reply writer, in order: the first request's reply would be there.
  EXPECT_EQ(reply_count(90), 0u);
  EXPECT_TRUE(log_.contains(LogLevel::kWarn, "dropped unanswered"));
  // And the bridge goes on serving.
  ASSERT_NO_FATAL_FAILURE(
      send(get(92, 1, cdn127::class_id::kIdentity, cdn127::identity_attr::kVendor)));
  const auto vendor = reply(92);
  ASSERT_TRUE(vendor);
  EXPECT_EQ(vendor->status, kSuccess) << vendor->message;
}

TEST_F(ExplicitTest, RepeatedRequestGetsTheSameReplyAndIsNotExecutedTwice) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  auto wire = std::make_shared<WireCount>();
  on_port([wire](sim::SimBackend& b) {
    b.world().bus().set_tap([wire](const sim::WireFrame& w) {
      const auto& f = w.frame;
      if (f.id == group2_id(mac_id(1), Group2Message::kMasterExplicitRequest) && f.len == 5 &&
          f.data[1] == 0x0E && f.data[2] == cdn127::class_id::kIdentity &&
          f.data[4] == cdn127::identity_attr::kSerialNumber) {
        ++wire->serial_number_requests;
      }
    });
  });

  const Request serial =
      get(7, 1, cdn127::class_id::kIdentity, cdn127::identity_attr::kSerialNumber);
  ASSERT_NO_FATAL_FAILURE(send(serial));
  const auto first = reply(7);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->status, kSuccess);
  EXPECT_FALSE(first->data.empty());  // UINT per the manual (seeds/README.md: or UDINT)

  ASSERT_NO_FATAL_FAILURE(send(serial));  // the requester did not see the reply: asks again
  const auto again = reply(7, 1);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->status, first->status);
  EXPECT_EQ(again->data, first->data);
  EXPECT_EQ(again->message, first->message);

  // GET_STATUS of the completed transaction tells the same.
  Request status = serial;
  status.command = dnbridge_COMMAND_GET_STATUS;
  ASSERT_NO_FATAL_FAILURE(send(status));
  const auto told = reply(7, 2);
  ASSERT_TRUE(told);
  EXPECT_EQ(told->status, kSuccess);
  EXPECT_EQ(told->data, first->data);

  // Executed once on the wire. The probe runs on the port's thread after
  // every frame so far, so the count is final.
  EXPECT_EQ(on_port([wire](sim::SimBackend&) { return wire->serial_number_requests.load(); }), 1u);
  EXPECT_EQ(reply_count(7), 3u);
}

TEST_F(ExplicitTest, RefusalsHaveTheirStatusCodes) {
  auto config = rack_config();
  // Node 7 is configured for another product: the master will not connect.
  config.ports[0].nodes[6].pump.identity = devicenet::ExpectedIdentity{59, 27, 9999};
  ASSERT_NO_FATAL_FAILURE(make_bridge(config));

  // 5: sent before the port runs (it checks its own MAC for 2 s first).
  ASSERT_NO_FATAL_FAILURE(send(get(5, 1, cdn127::class_id::kIdentity, 1)));
  start_bridge();
  auto r = reply(5);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kPortOffline) << r->message;

  auto ready = [&] {
    for (unsigned mac = 1; mac <= kPumps; ++mac) {
      const auto* n = nodes_.latest(pump_mac(mac));
      const auto want = mac == 7 ? dnbridge_NODE_WRONG_DEVICE : dnbridge_NODE_ONLINE;
      if (!n || n->state != want) return false;
    }
    return true;
  };
  ASSERT_TRUE(nodes_.until(ready, seconds(10)));

  // 3: a MAC that is not in the scan list, and one that is no MAC at all.
  ASSERT_NO_FATAL_FAILURE(send(get(3, 40, 1, 1)));
  r = reply(3);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kNotInScanList) << r->message;
  ASSERT_NO_FATAL_FAILURE(send(get(30, 200, 1, 1)));
  r = reply(30);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kNotInScanList) << r->message;

  // 6: the status of a transaction there never was.
  Request unknown = get(6, 1, 1, 1);
  unknown.command = dnbridge_COMMAND_GET_STATUS;
  ASSERT_NO_FATAL_FAILURE(send(unknown));
  r = reply(6);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kTxidUnknown) << r->message;

  // 8: a command that is not 1, 2 or 3.
  Request invalid = get(8, 1, 1, 1);
  invalid.command = 7;
  ASSERT_NO_FATAL_FAILURE(send(invalid));
  r = reply(8);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kInvalidCommand) << r->message;

  // 10: a txid already used for another request.
  ASSERT_NO_FATAL_FAILURE(send(get(10, 1, cdn127::class_id::kIdentity, 1)));
  r = reply(10);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kSuccess);
  ASSERT_NO_FATAL_FAILURE(send(get(10, 1, cdn127::class_id::kIdentity, 2)));
  r = reply(10, 1);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kOtherTransaction) << r->message;

  // 11: the node with the wrong identity.
  ASSERT_NO_FATAL_FAILURE(send(get(11, 7, 1, 1)));
  r = reply(11);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kCouldNotConnect) << r->message;
  EXPECT_NE(r->message.find("wrong device"), std::string::npos) << r->message;

  // 13: a port this rack does not have (answered by the DDS input itself).
  Request port = get(13, 1, 1, 1);
  port.port = "Z";
  ASSERT_NO_FATAL_FAILURE(send(port));
  r = reply(13);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kInvalidPort) << r->message;

  // 14: more service data than an explicit message carries.
  Request big = get(14, 1, 1, 1);
  big.service = 0x10;  // Set_Attribute_Single
  big.data.assign(600, 0);
  ASSERT_NO_FATAL_FAILURE(send(big));
  r = reply(14);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kInvalidSize) << r->message;

  // A request for another rack is left to that rack's bridge: no reply.
  Request other_rack = get(99, 1, 1, 1);
  other_rack.rack = "another-rack";
  ASSERT_NO_FATAL_FAILURE(send(other_rack));

  // 4: a node that went off the bus.
  on_port([](sim::SimBackend& b) { slave(b, 2).disconnect(); });
  const auto pulled = SteadyClock::now();
  ASSERT_TRUE(pumps_.until([&] {
    const auto* s = pumps_.latest(pump_mac(2));
    return s && !s->online;
  }));
  report("node 2 off the bus -> PumpState online false", ms_since(pulled));
  ASSERT_NO_FATAL_FAILURE(send(get(4, 2, 1, 1)));
  r = reply(4);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, kSlaveOffline) << r->message;

  EXPECT_EQ(reply_count(99), 0u);
}

TEST_F(ExplicitTest, InProgressBusyAndOutOfBuffersUnderLoad) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  // Slow devices: every explicit response of nodes 1..7 reaches the bus
  // 400 ms late, so that transactions stay in progress while more come.
  constexpr Duration kLate = milliseconds(400);
  on_port([kLate](sim::SimBackend& b) {
    for (unsigned mac = 1; mac <= 7; ++mac) {
      b.world().bus().faults().add(sim::FaultRule::delay_by(
          group2_id(mac_id(mac), Group2Message::kSlaveExplicitResponse), kLate));
    }
  });

  // Node 1: more requests than its explicit connection queues.
  for (std::uint32_t txid = 100; txid < 108; ++txid) {
    ASSERT_NO_FATAL_FAILURE(
        send(get(txid, 1, cdn127::class_id::kIdentity, cdn127::identity_attr::kVendor)));
  }
  // 2: asked while the first is still waiting for the device.
  Request status = get(100, 1, cdn127::class_id::kIdentity, cdn127::identity_attr::kVendor);
  status.command = dnbridge_COMMAND_GET_STATUS;
  ASSERT_NO_FATAL_FAILURE(send(status));
  // Nodes 2..7, five each (within their queues): more than one requester's
  // share of the transactions a port runs at once.
  for (std::uint32_t mac = 2; mac <= 7; ++mac) {
    for (std::uint32_t i = 0; i < 5; ++i) {
      ASSERT_NO_FATAL_FAILURE(send(get(200 + 10 * mac + i, mac, cdn127::class_id::kIdentity,
                                       cdn127::identity_attr::kVendor)));
    }
  }

  auto first = reply(100);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->status, kInProgress) << first->message;
  auto done = reply(100, 1);
  ASSERT_TRUE(done);
  EXPECT_EQ(done->status, kSuccess) << done->message;
  EXPECT_EQ(done->data, (std::vector<std::uint8_t>{59, 0}));

  // Node 1's requests: executed in order until its connection was busy.
  std::vector<std::uint8_t> node1;
  for (std::uint32_t txid = 100; txid < 108; ++txid) {
    const auto r = reply(txid, txid == 100 ? 1 : 0, seconds(8));
    ASSERT_TRUE(r) << txid;
    node1.push_back(r->status);
  }
  const auto busy_from = std::find(node1.begin(), node1.end(), kConnectionBusy);
  ASSERT_NE(busy_from, node1.end()) << "no request found the connection busy";
  EXPECT_GE(busy_from - node1.begin(), 4) << "busy before a few were queued";
  EXPECT_TRUE(std::all_of(node1.begin(), busy_from, [](auto s) { return s == kSuccess; }));
  EXPECT_TRUE(std::all_of(busy_from, node1.end(), [](auto s) { return s == kConnectionBusy; }));
  const auto in_progress_of_node1 = static_cast<unsigned>(busy_from - node1.begin());

  // The rest: accepted while this requester has fewer than 8 in progress
  // (its share of the port's 32), then out of buffers.
  unsigned accepted = in_progress_of_node1;
  unsigned out_of_buffers = 0;
  for (std::uint32_t mac = 2; mac <= 7; ++mac) {
    for (std::uint32_t i = 0; i < 5; ++i) {
      const auto r = reply(200 + 10 * mac + i, 0, seconds(8));
      ASSERT_TRUE(r) << mac << "/" << i;
      if (r->status == kSuccess) {
        ++accepted;
        EXPECT_EQ(out_of_buffers, 0u) << "accepted after the table was full";
      } else {
        EXPECT_EQ(r->status, kOutOfBuffers) << r->message;
        ++out_of_buffers;
      }
    }
  }
  EXPECT_EQ(accepted, 8u);
  EXPECT_EQ(out_of_buffers, in_progress_of_node1 + 30 - 8);
}

}  // namespace
}  // namespace dnbridge::e2e
