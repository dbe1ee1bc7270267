// The RAII layer itself: names, set-up errors, waitsets and guard
// conditions, read conditions and instance look-up.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "adapters/dds/discovered_participants.hpp"
#include "dds_fixture.hpp"

namespace dnbridge::dds::testing {
namespace {

Owned<dnbridge_PortStatus> port_status(const std::string& rack, const char* port) {
  Owned<dnbridge_PortStatus> p;
  set_string(p->rack, rack);
  set_string(p->port, port);
  return p;
}

TEST_F(DdsTest, ParticipantIsNamedAfterTheRack) {
  auto name = participant_.entity_name();
  ASSERT_TRUE(name.ok());
  EXPECT_EQ(*name, "dnbridge " + rack_);
  EXPECT_EQ(participant_.domain(), test_domain());
}

// Discovery tells every participant which rack a bridge serves (its name)
// and where it runs (its user data): host, process, version.
TEST(Discovery, ABridgeSaysItsRackAndHost) {
  const std::string user_data = host_user_data("9.8.7");
  Participant bridge(test_domain(), "rack-with-host", {}, user_data);
  Participant client(test_domain(), Participant::ClientName{"discovery test"});
  DiscoveredParticipants discovered(client);
  char host[256] = {};
  ASSERT_EQ(gethostname(host, sizeof host - 1), 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  std::optional<DiscoveredParticipant> found;
  while (!found && std::chrono::steady_clock::now() < deadline) {
    auto taken = discovered.take();
    ASSERT_TRUE(taken.ok());
    for (auto& p : *taken) {
      if (bridge_rack(p.name) == std::optional<std::string>("rack-with-host")) found = p;
    }
    if (!found) (void)wait_for(client, discovered, std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->user_data, user_data);
  EXPECT_EQ(user_data_field(found->user_data, "host"), host);
  EXPECT_EQ(user_data_field(found->user_data, "pid"), std::to_string(getpid()));
  EXPECT_EQ(user_data_field(found->user_data, "version"), "9.8.7");
  EXPECT_EQ(user_data_field(found->user_data, "rack"), "");
}

TEST_F(DdsTest, InvalidTopicNameThrowsWithWhatWasAttempted) {
  try {
    Topic<dnbridge_PumpState> topic(participant_, "dnbridge/Pump State!");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), DDS_RETCODE_BAD_PARAMETER);
    const std::string what = e.what();
    EXPECT_NE(what.find("creating topic \"dnbridge/Pump State!\""), std::string::npos) << what;
    EXPECT_NE(what.find("dnbridge::PumpState"), std::string::npos) << what;
    EXPECT_NE(what.find(dds_strretcode(DDS_RETCODE_BAD_PARAMETER)), std::string::npos) << what;
  }
}

TEST_F(DdsTest, InconsistentQosThrows) {
  Topic<dnbridge_PortStatus> topic(participant_);
  Qos qos = state_reader_qos();
  qos.keep_last(8).resource_limits(4, 1, 4);  // depth beyond max_samples_per_instance
  EXPECT_THROW(Reader<dnbridge_PortStatus>(participant_, topic, qos), Error);
}

TEST_F(DdsTest, RunTimeErrorsAreValuesInTheDdsCategory) {
  Topic<dnbridge_PortStatus> topic(participant_);
  Writer<dnbridge_PortStatus> writer(participant_, topic, state_writer_qos(seconds(1)));
  const dds_entity_t handle = writer.handle();
  Writer<dnbridge_PortStatus> moved(std::move(writer));
  EXPECT_EQ(moved.handle(), handle);
  EXPECT_FALSE(writer);  // NOLINT(bugprone-use-after-move): moved-from owns nothing
  moved.reset();
  const Status status = moved.write(*port_status(rack_, "p"));
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().category().name(), std::string("dds"));
  EXPECT_FALSE(status.error().message().empty());
}

TEST_F(DdsTest, GuardConditionWakesAWaitSetFromAnotherThread) {
  WaitSet waitset(participant_);
  GuardCondition wake(participant_);
  waitset.attach(wake, 42);

  std::thread other([&wake] { EXPECT_TRUE(wake.trigger().ok()); });
  auto triggered = waitset.wait(kEventTimeout);
  other.join();
  ASSERT_TRUE(triggered.ok());
  ASSERT_EQ(triggered->size(), 1U);
  EXPECT_EQ((*triggered)[0], 42);

  EXPECT_TRUE(wake.take_triggered().value());
  EXPECT_FALSE(wake.take_triggered().value());
  // Reset: the next wait times out with nothing triggered.
  triggered = waitset.wait(milliseconds(1));
  ASSERT_TRUE(triggered.ok());
  EXPECT_TRUE(triggered->empty());
}

TEST_F(DdsTest, WaitSetReportsTheTokensOfWhatTriggered) {
  Topic<dnbridge_PortStatus> topic(participant_);
  Reader<dnbridge_PortStatus> reader(participant_, topic, state_reader_qos());
  Writer<dnbridge_PortStatus> writer(participant_, topic, state_writer_qos(seconds(1)));
  ReadCondition data(reader, DDS_NOT_READ_SAMPLE_STATE);
  GuardCondition wake(participant_);
  WaitSet waitset(participant_);
  waitset.attach(data, 1);
  waitset.attach(wake, 2);

  ASSERT_TRUE(writer.write(*port_status(rack_, "p")).ok());
  auto triggered = waitset.wait(kEventTimeout);
  ASSERT_TRUE(triggered.ok());
  ASSERT_EQ(triggered->size(), 1U);
  EXPECT_EQ((*triggered)[0], 1);

  ASSERT_TRUE(waitset.detach(data).ok());
  ASSERT_TRUE(wake.trigger().ok());
  triggered = waitset.wait(kEventTimeout);
  ASSERT_TRUE(triggered.ok());
  ASSERT_EQ(triggered->size(), 1U);
  EXPECT_EQ((*triggered)[0], 2);
}

TEST_F(DdsTest, ReadConditionSelectsBySampleState) {
  Topic<dnbridge_PortStatus> topic(participant_);
  Reader<dnbridge_PortStatus> reader(participant_, topic, state_reader_qos());
  Writer<dnbridge_PortStatus> writer(participant_, topic, state_writer_qos(seconds(1)));
  ReadCondition not_read(reader, DDS_NOT_READ_SAMPLE_STATE);
  ReadCondition already_read(reader, DDS_READ_SAMPLE_STATE);
  ASSERT_TRUE(writer.write(*port_status(rack_, "p")).ok());
  ASSERT_TRUE(wait_for(participant_, not_read));

  auto read = reader.read();  // leaves it, marked read
  ASSERT_EQ(read->size(), 1U);
  EXPECT_TRUE((*read)[0].info().first_read());
  EXPECT_TRUE(reader.take(not_read)->empty());
  auto taken = reader.take(already_read);
  ASSERT_EQ(taken->size(), 1U);
  EXPECT_FALSE((*taken)[0].info().first_read());
  EXPECT_TRUE(reader.read()->empty());

  // A condition of another reader is refused, not misused.
  Reader<dnbridge_PortStatus> other(participant_, topic, state_reader_qos());
  ReadCondition others(other, DDS_ANY_STATE);
  EXPECT_FALSE(reader.take(others).ok());
}

TEST_F(DdsTest, LookupInstanceAndTakeInstance) {
  Topic<dnbridge_PortStatus> topic(participant_);
  Reader<dnbridge_PortStatus> reader(participant_, topic, state_reader_qos());
  Writer<dnbridge_PortStatus> writer(participant_, topic, state_writer_qos(seconds(1)));
  ASSERT_TRUE(writer.write(*port_status(rack_, "a")).ok());
  ASSERT_TRUE(writer.write(*port_status(rack_, "b")).ok());
  ASSERT_TRUE(writer.wait_for_acks(kEventTimeout).ok());

  EXPECT_EQ(reader.lookup_instance(*port_status(rack_, "unknown")), DDS_HANDLE_NIL);
  const dds_instance_handle_t b = reader.lookup_instance(*port_status(rack_, "b"));
  ASSERT_NE(b, DDS_HANDLE_NIL);
  auto taken = reader.take_instance(b);
  ASSERT_TRUE(taken.ok());
  ASSERT_EQ(taken->size(), 1U);
  EXPECT_EQ(view((*taken)[0]->port), "b");
  EXPECT_EQ((*taken)[0].info().instance_handle(), b);
  EXPECT_EQ(reader.take()->size(), 1U);  // "a" is still there
}

TEST_F(DdsTest, MatchedCounts) {
  Topic<dnbridge_PortStatus> topic(participant_);
  Writer<dnbridge_PortStatus> writer(participant_, topic, state_writer_qos(seconds(1)));
  ASSERT_TRUE(writer.set_status_mask(DDS_PUBLICATION_MATCHED_STATUS).ok());
  EXPECT_EQ(writer.matched_subscriptions().value(), 0U);
  Reader<dnbridge_PortStatus> reader(participant_, topic, state_reader_qos());
  ASSERT_TRUE(wait_for(participant_, writer));
  EXPECT_EQ(writer.matched_subscriptions().value(), 1U);
  EXPECT_EQ(reader.matched_publications().value(), 1U);
}

// A bridge's participant that is the first of its process in its domain
// creates the domain (with the bridge's settings, participant.cpp) and
// deletes it when it goes, unless another participant is still in it.
TEST(BridgeDomain, GoesWithTheBridgeParticipantUnlessAnotherIsLeftInIt) {
  // A domain no other participant of this process is in (test domains are
  // 100 to 199; another process's is told apart by its discovery tag).
  const dds_domainid_t domain = test_domain() < 150 ? test_domain() + 50 : test_domain() - 50;
  {
    Participant bridge(domain, "domain-test");
    EXPECT_EQ(dds_create_domain(domain, nullptr), DDS_RETCODE_PRECONDITION_NOT_MET);
  }
  const dds_entity_t again = dds_create_domain(domain, nullptr);
  ASSERT_GT(again, 0) << "the domain outlived its bridge participant";
  ASSERT_EQ(dds_delete(again), DDS_RETCODE_OK);

  // The settings Cyclone read for the domain (its trace of the
  // configuration), the operator's CYCLONEDDS_URI after them.
  const char* set = std::getenv("CYCLONEDDS_URI");
  ASSERT_NE(set, nullptr) << "the loopback environment sets CYCLONEDDS_URI";
  const std::string uri = set;
  const std::string trace =
      ::testing::TempDir() + "bridge-domain-" + std::to_string(getpid()) + ".log";
  ASSERT_EQ(setenv("CYCLONEDDS_URI",
                   (uri + ",<Tracing><Category>config</Category><OutputFile>" + trace +
                    "</OutputFile></Tracing>")
                       .c_str(),
                   1),
            0);
  auto bridge = std::make_unique<Participant>(domain, "domain-test");
  ASSERT_EQ(setenv("CYCLONEDDS_URI", uri.c_str(), 1), 0);
  std::ifstream file(trace);
  std::stringstream read;
  read << file.rdbuf();
  const std::string config = read.str();
  for (const char* setting :
       {"Watermarks/WhcAdaptive/#text: false {0}", "Watermarks/WhcHighInit/#text: 4 MiB {0}",
        "Watermarks/WhcHigh/#text: 4 MiB {0}", "Tracing/OutputFile"}) {
    EXPECT_NE(config.find(setting), std::string::npos) << setting << " not in " << trace;
  }
  std::remove(trace.c_str());

  Participant client(domain, Participant::ClientName{"domain-test client"});
  bridge.reset();
  EXPECT_TRUE(client.entity_name().ok()) << "the client's participant went with the bridge's";
  const dds_entity_t left = dds_get_parent(client.handle());
  ASSERT_GT(left, 0);
  EXPECT_EQ(dds_delete(left), DDS_RETCODE_OK);  // and with it the client's participant
}

}  // namespace
}  // namespace dnbridge::dds::testing
