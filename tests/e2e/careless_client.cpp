// dnbridge_careless_client: a DDS client of the bridge that misbehaves in one
// chosen way, as a process of its own (tests/e2e/careless_client_test.cpp
// runs it). What it does to the bridge must not cost the bridge's other
// clients anything.
//
//   dnbridge_careless_client DOMAIN MODE ARGS...
//
// It talks with the test a line at a time on stdin and stdout (a socket,
// ChildOptions::control): it prints what it has done once its endpoints were
// matched and its samples written, and reads what to do next; at the end of
// its stdin it exits. Errors go to stderr with exit status 1; a usage error
// exits with 2. CYCLONEDDS_URI (loopback, the test's discovery tag) comes from
// the test's environment.
//
// Modes:
//   ahead MAC STRENGTH LEASE_MS AHEAD_S ISSUER
//       a commander whose clock runs AHEAD_S seconds ahead: writes PumpCommand
//       MAC on (n2 ballast on, analog 4000) with the documented command writer
//       QoS and that strength and lease, stamped now + AHEAD_S; prints
//       "written"; on the line "exit" (or the end of stdin) deletes its writer
//       and exits.
//   requests REQUESTER COUNT
//       COUNT ExplicitRequests under distinct txids (1..COUNT; Gets of the
//       Identity vendor of nodes 1..8 in turn), never unregistered; prints
//       "written COUNT acked" or "written COUNT unacked" (whether the bridge
//       acknowledged them within 5 s); stays until the end of stdin.
//   stall-replies REQUESTER REPEATS GETS
//       an ExplicitReply reader with an early reply QoS (keep-all, at most 4
//       samples per instance), never taken from: once it holds 4 replies it
//       rejects the next, and Cyclone's delivery in this process waits for
//       it (synchronous delivery: its receive thread waits, so this process
//       acknowledges nothing more on any topic). Readers of PumpState,
//       NodeStatus and PortStatus as well, matched before the stall, which
//       then acknowledge nothing either. Writes one request (txid 1) again
//       each time a reply came, until the reader rejects one (at most
//       REPEATS times), prints "stalled after N" (or "not stalled after N");
//       on the line "gets" writes GETS Gets (txids 2..GETS+1, nodes 1..8 in
//       turn), prints "sent OK FAILED" (writes that succeeded and failed);
//       answers the line "status" with "rejected N" (replies its reader
//       rejected); stays until the end of stdin.
//   flood ISSUER STRENGTH COUNT
//       a commander that writes COUNT PumpCommands back to back, with the
//       documented command writer QoS and that strength, round robin over
//       pumps 1..4 (pump on, analog output the command's number modulo
//       4096), then one
//       more for each of them (pump on, n2 ballast on, analog 4000 + MAC);
//       prints "written" once all are acknowledged; stays until the end of
//       stdin.
//   three-writers STRENGTH LEASE_MS READERS
//       three PumpCommand writers in this one participant with the documented
//       command writer QoS, writer N commanding pump N on (analog 100 x N,
//       issuer "writer-N") once matched with READERS readers; prints
//       "written"; on a line "delete N M ..." deletes those writers back to
//       back and prints "deleted"; on "write N" writes writer N's command
//       again and prints "written"; the writers left live until the end of
//       stdin.
//   commander MAC STRENGTH LEASE_MS DEADLINE_MS ISSUER
//       a commander with the documented command writer QoS and that strength,
//       liveliness lease (0: infinite) and deadline (0: none). Prints
//       "matched" once a bridge's command reader matched it, or "refused P"
//       when one refused it with an incompatible QoS (P: the policy's ID).
//       On "write" it writes PumpCommand MAC on (n2 ballast on, analog
//       4000) and prints "written"; on "refresh MS" writes it every MS
//       milliseconds from a thread of its own ("refreshing"), until
//       "silent" ("silent": its DDS stack stays alive, nothing more is
//       written); on "unregister" it unregisters the instance and prints
//       "unregistered"; at the end of stdin it deletes its writer and exits.
//   state-reader
//       a PumpState reader with the documented state QoS, never taken from;
//       prints "receiving" once it holds a sample; stays until the end of
//       stdin. Stopped (SIGSTOP), it is a reader that acknowledges nothing.
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"
#include "client_samples.hpp"

namespace dnbridge::careless {
namespace {

using e2e::get_vendor;
using e2e::pump_command;

constexpr unsigned kPumps = 8;
constexpr Duration kMatchTimeout = seconds(10);
constexpr Duration kAckTimeout = seconds(5);
// A write that timed out waiting for room is made again this many times.
constexpr int kWritesAgain = 50;

[[noreturn]] void fail(const std::string& what) {
  std::cerr << "dnbridge_careless_client: " << what << std::endl;
  std::exit(1);
}

void say(const std::string& line) { std::cout << line << std::endl; }

// The next line of stdin; false at its end.
bool next_line(std::string& line) { return static_cast<bool>(std::getline(std::cin, line)); }

// Until `entity` (a writer or reader whose matched status is read by
// `count`) has at least `wanted` matches, or the timeout.
template <class Count>
void await_match(const dds::Participant& participant, const dds::Entity& entity, uint32_t mask,
                 Count count, const char* what, uint32_t wanted = 1) {
  if (!entity.set_status_mask(mask)) fail(std::string("status mask of ") + what);
  dds::WaitSet waitset(participant);
  waitset.attach(entity, 1);
  const auto deadline = std::chrono::steady_clock::now() + kMatchTimeout;
  while (count() < wanted) {
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= Duration::zero()) fail(std::string("no match for ") + what);
    (void)waitset.wait(std::chrono::duration_cast<Duration>(left));
  }
}

template <class T>
void await_reader(const dds::Participant& participant, const dds::Writer<T>& writer,
                  const char* what, uint32_t readers = 1) {
  await_match(
      participant, writer, DDS_PUBLICATION_MATCHED_STATUS,
      [&] { return writer.matched_subscriptions().value_or(0); }, what, readers);
}

template <class T>
void await_writer(const dds::Participant& participant, const dds::Reader<T>& reader,
                  const char* what) {
  await_match(
      participant, reader, DDS_SUBSCRIPTION_MATCHED_STATUS,
      [&] { return reader.matched_publications().value_or(0); }, what);
}

unsigned node_of(std::uint32_t n) { return 1 + n % kPumps; }

int ahead(dds_domainid_t domain, unsigned mac, std::int32_t strength, Duration lease,
          Duration ahead_by, const std::string& issuer) {
  dds::Participant participant(domain, dds::Participant::ClientName{issuer});
  dds::Topic<dnbridge_PumpCommand> topic(participant);
  auto writer = std::make_unique<dds::Writer<dnbridge_PumpCommand>>(
      participant, topic, dds::command_writer_qos(e2e::sim_rack_partitions(), strength, lease));
  await_reader(participant, *writer, "the PumpCommand writer");
  if (!writer->write(*pump_command(mac, true, true, 4000, issuer), dds::dds_now() + ahead_by)) {
    fail("writing the command");
  }
  if (!writer->wait_for_acks(kAckTimeout)) fail("the command was not acknowledged");
  say("written");
  std::string line;
  while (next_line(line) && line != "exit") {
  }
  writer.reset();  // unregisters its instance, stamped with this (wrong) clock's now
  return 0;
}

int commander(dds_domainid_t domain, unsigned mac, std::int32_t strength, Duration lease,
              Duration deadline, const std::string& issuer) {
  dds::Participant participant(domain, dds::Participant::ClientName{issuer});
  dds::Topic<dnbridge_PumpCommand> topic(participant);
  dds::Writer<dnbridge_PumpCommand> writer(
      participant, topic,
      dds::command_writer_qos(
          e2e::sim_rack_partitions(), strength, lease == Duration::zero() ? dds::kInfinite : lease,
          deadline == Duration::zero() ? std::nullopt : std::optional<Duration>(deadline)));
  if (!writer.set_status_mask(DDS_PUBLICATION_MATCHED_STATUS |
                              DDS_OFFERED_INCOMPATIBLE_QOS_STATUS)) {
    fail("status mask of the PumpCommand writer");
  }
  {
    dds::WaitSet waitset(participant);
    waitset.attach(writer, 1);
    const auto until = std::chrono::steady_clock::now() + kMatchTimeout;
    for (;;) {
      dds_offered_incompatible_qos_status_t refused{};
      if (dds_get_offered_incompatible_qos_status(writer.handle(), &refused) == DDS_RETCODE_OK &&
          refused.total_count > 0) {
        say("refused " + std::to_string(refused.last_policy_id));
        break;
      }
      if (writer.matched_subscriptions().value_or(0) > 0) {
        say("matched");
        break;
      }
      const auto left = until - std::chrono::steady_clock::now();
      if (left <= Duration::zero()) fail("neither matched nor refused");
      (void)waitset.wait(std::chrono::duration_cast<Duration>(left));
    }
  }
  const auto command = pump_command(mac, true, true, 4000, issuer);
  std::mutex mutex;
  std::condition_variable changed;
  bool refreshing = false;
  bool done = false;
  Duration period{};
  std::thread refresher([&] {
    std::unique_lock lock(mutex);
    for (;;) {
      changed.wait(lock, [&] { return refreshing || done; });
      if (done) return;
      if (!writer.write(*command)) fail("writing the command");
      changed.wait_for(lock, period, [&] { return !refreshing || done; });
    }
  });
  std::string line;
  while (next_line(line)) {
    if (line == "write") {
      if (!writer.write(*command)) fail("writing the command");
      say("written");
    } else if (line.rfind("refresh ", 0) == 0) {
      {
        std::lock_guard lock(mutex);
        period = milliseconds(std::stol(line.substr(8)));
        refreshing = true;
      }
      changed.notify_all();
      say("refreshing");
    } else if (line == "unregister") {
      if (!writer.unregister_instance(*command)) fail("unregistering the command's instance");
      say("unregistered");
    } else if (line == "silent") {
      {
        std::lock_guard lock(mutex);
        refreshing = false;
      }
      changed.notify_all();
      say("silent");
    }
  }
  {
    std::lock_guard lock(mutex);
    done = true;
  }
  changed.notify_all();
  refresher.join();
  return 0;
}

int requests(dds_domainid_t domain, const std::string& requester, std::uint32_t count) {
  dds::Participant participant(domain, dds::Participant::ClientName{requester});
  dds::Topic<dnbridge_ExplicitRequest> topic(participant);
  dds::Writer<dnbridge_ExplicitRequest> writer(participant, topic,
                                               dds::request_writer_qos(e2e::sim_rack_partitions()));
  await_reader(participant, writer, "the ExplicitRequest writer");
  for (std::uint32_t txid = 1; txid <= count; ++txid) {
    // The writer's history holds kRequestWriterMaxSamples unacknowledged
    // requests: past that a write waits, then times out, and is made again.
    const auto request = get_vendor(requester, txid, node_of(txid));
    Status status = writer.write(*request);
    for (int again = 0; !status && status.error() == dds::make_error_code(DDS_RETCODE_TIMEOUT) &&
                        again < kWritesAgain;
         ++again) {
      status = writer.write(*request);
    }
    if (!status) fail("writing request " + std::to_string(txid) + ": " + status.error().message());
  }
  const bool acked = static_cast<bool>(writer.wait_for_acks(kAckTimeout));
  say("written " + std::to_string(count) + (acked ? " acked" : " unacked"));
  std::string line;
  while (next_line(line)) {
  }
  // Ends without deleting anything: whatever the bridge holds of this client
  // it holds until the client's lease ends.
  std::_Exit(0);
}

int state_reader(dds_domainid_t domain) {
  dds::Participant participant(domain, dds::Participant::ClientName{"state-reader"});
  dds::Topic<dnbridge_PumpState> topic(participant);
  dds::Reader<dnbridge_PumpState> reader(participant, topic, dds::state_reader_qos());
  dds::ReadCondition any(reader, DDS_ANY_STATE);
  dds::WaitSet waitset(participant);
  waitset.attach(any, 1);
  const auto deadline = std::chrono::steady_clock::now() + kMatchTimeout;
  for (;;) {
    auto held = reader.read();
    if (held.ok() && !held->empty()) break;
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= Duration::zero()) fail("no PumpState sample");
    (void)waitset.wait(std::chrono::duration_cast<Duration>(left));
  }
  say("receiving");
  std::string line;
  while (next_line(line)) {
  }
  return 0;
}

// The reply reader's QoS before the bridge's readers stopped refusing
// samples: keep-all within resource limits.
dds::Qos rejecting_reply_reader_qos() {
  dds::Qos qos;
  qos.partitions(e2e::sim_rack_partitions());
  qos.reliable(milliseconds(100))
      .durability(dds::Durability::kTransientLocal)
      .keep_all()
      .resource_limits(8192, 8192, 4);
  return qos;
}

int stall_replies(dds_domainid_t domain, const std::string& requester, std::uint32_t repeats,
                  std::uint32_t gets) {
  dds::Participant participant(domain, dds::Participant::ClientName{requester});
  dds::Topic<dnbridge_ExplicitRequest> request_topic(participant);
  dds::Topic<dnbridge_ExplicitReply> reply_topic(participant);
  dds::Reader<dnbridge_ExplicitReply> replies(participant, reply_topic,
                                              rejecting_reply_reader_qos());
  dds::Writer<dnbridge_ExplicitRequest> writer(participant, request_topic,
                                               dds::request_writer_qos(e2e::sim_rack_partitions()));
  dds::Topic<dnbridge_PumpState> pump_topic(participant);
  dds::Topic<dnbridge_NodeStatus> node_topic(participant);
  dds::Topic<dnbridge_PortStatus> port_topic(participant);
  dds::Reader<dnbridge_PumpState> pumps(participant, pump_topic, dds::state_reader_qos());
  dds::Reader<dnbridge_NodeStatus> nodes(participant, node_topic, dds::state_reader_qos());
  dds::Reader<dnbridge_PortStatus> ports(participant, port_topic, dds::state_reader_qos());
  await_writer(participant, replies, "the ExplicitReply reader");
  await_writer(participant, pumps, "the PumpState reader");
  await_writer(participant, nodes, "the NodeStatus reader");
  await_writer(participant, ports, "the PortStatus reader");
  await_reader(participant, writer, "the ExplicitRequest writer");
  std::uint32_t ok = 0;
  std::uint32_t failed = 0;
  const auto write = [&](std::uint32_t txid, unsigned mac) {
    if (writer.write(*get_vendor(requester, txid, mac))) {
      ++ok;
    } else {
      ++failed;
    }
  };
  const auto rejected = [&] {
    const auto status = replies.sample_rejected();
    return status ? status->total_count : 0;
  };
  // The same request again and again, each time once a reply came (a
  // repeat gets the same reply again), until the reader rejects one.
  if (!replies.set_status_mask(DDS_DATA_AVAILABLE_STATUS | DDS_SAMPLE_REJECTED_STATUS)) {
    fail("status mask of the reply reader");
  }
  dds::WaitSet waitset(participant);
  waitset.attach(replies, 1);
  std::uint32_t written = 0;
  while (rejected() == 0 && written < repeats) {
    write(1, 1);
    ++written;
    (void)waitset.wait(seconds(1));
    uint32_t status = 0;
    (void)dds_take_status(replies.handle(), &status, DDS_DATA_AVAILABLE_STATUS);
  }
  say((rejected() > 0 ? "stalled after " : "not stalled after ") + std::to_string(written));
  std::string line;
  while (next_line(line)) {
    if (line == "gets") {
      for (std::uint32_t txid = 2; txid < 2 + gets; ++txid) write(txid, node_of(txid));
      say("sent " + std::to_string(ok) + " " + std::to_string(failed));
    } else if (line == "status") {
      say("rejected " + std::to_string(rejected()));
    }
  }
  // Deleting a reader that Cyclone's delivery waits for may wait too.
  std::_Exit(0);
}

int flood(dds_domainid_t domain, const std::string& issuer, std::int32_t strength,
          std::uint32_t count) {
  constexpr unsigned kFloodPumps = 4;
  dds::Participant participant(domain, dds::Participant::ClientName{"flood"});
  dds::Topic<dnbridge_PumpCommand> topic(participant);
  dds::Writer<dnbridge_PumpCommand> writer(
      participant, topic,
      dds::command_writer_qos(e2e::sim_rack_partitions(), strength, seconds(10)));
  await_reader(participant, writer, "the PumpCommand writer");
  const auto write = [&](const dds::Owned<dnbridge_PumpCommand>& command) {
    if (!writer.write(*command)) fail("writing a command");
  };
  for (std::uint32_t i = 0; i < count; ++i) {
    write(pump_command(1 + i % kFloodPumps, true, false, static_cast<std::uint16_t>(i % 4096),
                       issuer));
  }
  for (unsigned mac = 1; mac <= kFloodPumps; ++mac) {
    write(pump_command(mac, true, true, static_cast<std::uint16_t>(4000 + mac), issuer));
  }
  if (!writer.wait_for_acks(kAckTimeout)) fail("the commands were not acknowledged");
  say("written");
  std::string line;
  while (next_line(line)) {
  }
  return 0;
}

int three_writers(dds_domainid_t domain, std::int32_t strength, Duration lease,
                  std::uint32_t readers) {
  dds::Participant participant(domain, dds::Participant::ClientName{"three writers"});
  dds::Topic<dnbridge_PumpCommand> topic(participant);
  std::vector<std::unique_ptr<dds::Writer<dnbridge_PumpCommand>>> writers;
  const auto write = [&](unsigned n) {
    return writers[n - 1]->write(*pump_command(n, true, false, static_cast<std::uint16_t>(100 * n),
                                               "writer-" + std::to_string(n)));
  };
  for (unsigned n = 1; n <= 3; ++n) {
    writers.push_back(std::make_unique<dds::Writer<dnbridge_PumpCommand>>(
        participant, topic, dds::command_writer_qos(e2e::sim_rack_partitions(), strength, lease)));
    await_reader(participant, *writers.back(), "a PumpCommand writer", readers);
    if (!write(n)) fail("writing a command");
  }
  for (const auto& w : writers) {
    if (!w->wait_for_acks(kAckTimeout)) fail("a command was not acknowledged");
  }
  say("written");
  // "delete N M ...": those writers, back to back, in that order;
  // "write N": writer N's command again.
  std::string line;
  while (next_line(line)) {
    std::istringstream words(line);
    std::string verb;
    words >> verb;
    if (verb == "delete") {
      for (unsigned n = 0; words >> n;) {
        if (n >= 1 && n <= writers.size()) writers[n - 1].reset();
      }
      say("deleted");
    } else if (unsigned n = 0;
               verb == "write" && words >> n && n >= 1 && n <= writers.size() && writers[n - 1]) {
      if (!write(n) || !writers[n - 1]->wait_for_acks(kAckTimeout)) fail("writing a command");
      say("written");
    }
  }
  return 0;
}

int usage() {
  std::cerr << "usage: dnbridge_careless_client DOMAIN ahead MAC STRENGTH LEASE_MS AHEAD_S ISSUER\n"
               "       dnbridge_careless_client DOMAIN requests REQUESTER COUNT\n"
               "       dnbridge_careless_client DOMAIN stall-replies REQUESTER REPEATS GETS\n"
               "       dnbridge_careless_client DOMAIN flood ISSUER STRENGTH COUNT\n"
               "       dnbridge_careless_client DOMAIN three-writers STRENGTH LEASE_MS READERS\n"
               "       dnbridge_careless_client DOMAIN state-reader\n"
               "       dnbridge_careless_client DOMAIN commander MAC STRENGTH LEASE_MS DEADLINE_MS "
               "ISSUER\n";
  return 2;
}

int run(const std::vector<std::string>& args) {
  if (args.size() < 2) return usage();
  const auto number = [&](std::size_t i) { return std::stol(args.at(i)); };
  const auto domain = static_cast<dds_domainid_t>(number(0));
  const std::string& mode = args[1];
  if (mode == "ahead" && args.size() == 7) {
    return ahead(domain, static_cast<unsigned>(number(2)), static_cast<std::int32_t>(number(3)),
                 milliseconds(number(4)), seconds(number(5)), args[6]);
  }
  if (mode == "requests" && args.size() == 4) {
    return requests(domain, args[2], static_cast<std::uint32_t>(number(3)));
  }
  if (mode == "stall-replies" && args.size() == 5) {
    return stall_replies(domain, args[2], static_cast<std::uint32_t>(number(3)),
                         static_cast<std::uint32_t>(number(4)));
  }
  if (mode == "flood" && args.size() == 5) {
    return flood(domain, args[2], static_cast<std::int32_t>(number(3)),
                 static_cast<std::uint32_t>(number(4)));
  }
  if (mode == "three-writers" && args.size() == 5) {
    return three_writers(domain, static_cast<std::int32_t>(number(2)), milliseconds(number(3)),
                         static_cast<std::uint32_t>(number(4)));
  }
  if (mode == "state-reader" && args.size() == 2) return state_reader(domain);
  if (mode == "commander" && args.size() == 7) {
    return commander(domain, static_cast<unsigned>(number(2)), static_cast<std::int32_t>(number(3)),
                     milliseconds(number(4)), milliseconds(number(5)), args[6]);
  }
  return usage();
}

}  // namespace
}  // namespace dnbridge::careless

int main(int argc, char** argv) {
  try {
    return dnbridge::careless::run(std::vector<std::string>(argv + 1, argv + argc));
  } catch (const std::invalid_argument&) {
    return dnbridge::careless::usage();
  } catch (const std::exception& e) {
    std::cerr << "dnbridge_careless_client: " << e.what() << std::endl;
    return 1;
  }
}
