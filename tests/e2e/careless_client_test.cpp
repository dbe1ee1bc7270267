// What a careless DDS client must not cost the bridge's other clients: three
// processes on loopback. The dnbridge executable on its embedded default rack
// (BridgeProcess: measured alone, its RSS read from /proc), a careless client
// (dnbridge_careless_client, tests/e2e/careless_client.cpp), and this
// process, the well-behaved client that checks what the bridge does for it.
//
// Every wait is for an event and bounded: a DDS waitset, a line from the
// careless client on its control socket, or its exit on a pidfd.
#include <sched.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "adapters/daemon/dds_publisher.hpp"
#include "adapters/port/steady_time.hpp"
#include "bridge_fixture.hpp"
#include "bridge_process.hpp"
#include "child_process.hpp"
#include "client_samples.hpp"

namespace dnbridge::e2e {
namespace {

// Puts the thread named `name` of process `pid` under SCHED_FIFO at the
// lowest real-time priority; false if there is no such thread or it may not.
bool thread_to_fifo(pid_t pid, const std::string& name) {
  const std::filesystem::path tasks = "/proc/" + std::to_string(pid) + "/task";
  std::error_code ec;
  for (std::filesystem::directory_iterator it(tasks, ec), end; !ec && it != end; it.increment(ec)) {
    std::ifstream comm(it->path() / "comm");
    std::string line;
    // The kernel keeps 15 characters of a thread's name.
    if (!std::getline(comm, line) || line != name.substr(0, 15)) continue;
    sched_param priority{};
    priority.sched_priority = 1;
    const auto tid = static_cast<pid_t>(std::stol(it->path().filename().string()));
    return sched_setscheduler(tid, SCHED_FIFO, &priority) == 0;
  }
  return false;
}

constexpr std::uint8_t kStatusSuccess = dnbridge_STATUS_SUCCESS;
constexpr std::uint16_t kVendorId = 59;  // the simulated CDN127's Identity vendor

// Takes what several subscriptions receive, waiting on all of them at once.
class Watch {
 public:
  explicit Watch(const dds::Participant& participant) : waitset_(participant) {}

  template <class T>
  void add(Subscription<T>& subscription) {
    conditions_.push_back(std::make_unique<dds::ReadCondition>(
        subscription.reader(),
        DDS_NOT_READ_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ANY_INSTANCE_STATE));
    waitset_.attach(*conditions_.back(), static_cast<dds::WaitSet::Token>(conditions_.size()));
    take_.push_back([&subscription] { subscription.take_all(); });
  }

  // Until `done` holds (true) or `timeout` passes (false); `done` is asked
  // after every take and at least every `slice`.
  bool until(const std::function<bool()>& done, Duration timeout,
             Duration slice = milliseconds(50)) {
    const auto deadline = SteadyClock::now() + timeout;
    for (;;) {
      for (auto& take : take_) take();
      if (done()) return true;
      const auto now = SteadyClock::now();
      if (now >= deadline) return false;
      (void)waitset_.wait(std::min<Duration>(slice, deadline - now));
    }
  }

 private:
  dds::WaitSet waitset_;
  std::vector<std::unique_ptr<dds::ReadCondition>> conditions_;
  std::vector<std::function<void()>> take_;
};

class CarelessClientTest : public ::testing::Test {
 protected:
  // The dnbridge process, every pump online as this client sees it.
  void start_bridge(const ChildOptions& options = {}) {
    const auto spawned = SteadyClock::now();
    bridge_.emplace(DNBRIDGE_BINARY, options);
    ASSERT_TRUE(bridge_->child().running());
    ASSERT_TRUE(pumps_.matched(1));
    ASSERT_TRUE(nodes_.matched(1));
    ASSERT_TRUE(pumps_.until([&] { return all_online(); }, seconds(15)));
    report("dnbridge process spawned -> every pump online", ms_since(spawned));
  }

  // The careless client, talking on its control socket.
  ChildProcess& careless(std::vector<std::string> args) {
    args.insert(args.begin(), {DNBRIDGE_CARELESS_CLIENT, std::to_string(test_domain())});
    ChildOptions options;
    options.control = true;
    careless_.emplace(std::move(args), options);
    return *careless_;
  }

  bool all_online() const {
    for (unsigned mac = 1; mac <= kPumps; ++mac) {
      const auto* s = pumps_.latest(pump_mac(mac));
      if (!s || !s->online || !s->inputs_valid) return false;
    }
    return true;
  }

  // PumpState says the device applied these outputs, commanded by `by`.
  bool echoes(unsigned mac, bool pump_on, bool n2, std::uint16_t analog,
              std::string_view by) const {
    const auto* s = pumps_.latest(pump_mac(mac));
    return s && s->online && !s->outputs_idle && s->pump_on == pump_on && s->n2_ballast_on == n2 &&
           s->analog_output_raw == analog && dds::view(s->commanded_by) == by;
  }
  bool idle(unsigned mac) const {
    const auto* s = pumps_.latest(pump_mac(mac));
    return s && s->online && s->outputs_idle && dds::view(s->commanded_by).empty();
  }

  template <class T>
  bool writer_matched(const dds::Writer<T>& writer) {
    return dds::testing::until_matched(supervisor_, writer);
  }

  // The vendor of node `mac` (one not in the scan list is refused at once).
  dds::Owned<dnbridge_ExplicitRequest> get_vendor(std::uint32_t txid, unsigned mac) const {
    return e2e::get_vendor(requester_, txid, mac);
  }

  // The replies `replies` took for (`requester`, txid) with txid in [first, last].
  static std::set<std::uint32_t> answered(const Subscription<dnbridge_ExplicitReply>& replies,
                                          std::string_view requester, std::uint32_t first,
                                          std::uint32_t last) {
    std::set<std::uint32_t> txids;
    for (const auto& r : replies.history()) {
      if (r.sample.valid_data() && dds::view(r.sample->requester) == requester &&
          r.sample->txid >= first && r.sample->txid <= last) {
        txids.insert(r.sample->txid);
      }
    }
    return txids;
  }

  // A requester's write or unregistration, made again while it times out:
  // the request writer's history holds kRequestWriterMaxSamples samples the
  // bridge has not acknowledged, and past that a write waits for at most its
  // max_blocking_time and then fails with DDS_RETCODE_TIMEOUT.
  template <class Op>
  static Status again_while_full(Op op) {
    Status status = op();
    for (int again = 0;
         !status && status.error() == dds::make_error_code(DDS_RETCODE_TIMEOUT) && again < 50;
         ++again) {
      status = op();
    }
    return status;
  }

  // Writes the well-behaved Get `txid` of node 1 and waits up to `timeout`
  // for its reply: its time in ms, or nullopt.
  std::optional<double> get_round_trip(const dds::Writer<dnbridge_ExplicitRequest>& requests,
                                       Subscription<dnbridge_ExplicitReply>& replies,
                                       std::uint32_t txid, Duration timeout) {
    const auto sent = SteadyClock::now();
    const auto request = get_vendor(txid, 1);
    if (!requests.write(*request)) return std::nullopt;
    const dnbridge_ExplicitReply* reply = nullptr;
    const bool got = replies.until(
        [&] {
          reply = replies.latest([&](const dnbridge_ExplicitReply& r) {
            return r.txid == txid && dds::view(r.requester) == requester_;
          });
          return reply != nullptr;
        },
        timeout);
    if (!got) return std::nullopt;
    const double ms = ms_since(sent);
    EXPECT_EQ(reply->status, kStatusSuccess) << dds::view(reply->message);
    const auto data = dds::view(reply->data);
    EXPECT_EQ(std::vector<std::uint8_t>(data.begin(), data.end()),
              (std::vector<std::uint8_t>{kVendorId & 0xFF, kVendorId >> 8}));
    (void)requests.unregister_instance(*request);
    return ms;
  }

  dds::Participant supervisor_{test_domain(), dds::Participant::ClientName{"e2e supervisor"}};
  dds::Topic<dnbridge_PumpState> pump_topic_{supervisor_};
  dds::Topic<dnbridge_NodeStatus> node_topic_{supervisor_};
  dds::Topic<dnbridge_PortStatus> port_topic_{supervisor_};
  dds::Topic<dnbridge_PumpCommand> command_topic_{supervisor_};
  dds::Topic<dnbridge_ExplicitRequest> request_topic_{supervisor_};
  dds::Topic<dnbridge_ExplicitReply> reply_topic_{supervisor_};
  Subscription<dnbridge_PumpState> pumps_{supervisor_, pump_topic_, dds::state_reader_qos()};
  Subscription<dnbridge_NodeStatus> nodes_{supervisor_, node_topic_, dds::state_reader_qos()};
  Subscription<dnbridge_PortStatus> ports_{supervisor_, port_topic_, dds::state_reader_qos()};
  const std::string requester_ = "e2e@" + std::to_string(getpid());

  // Killed (if still running) before the bridge.
  std::optional<BridgeProcess> bridge_;
  std::optional<ChildProcess> careless_;
};

// 1. A commander whose clock runs an hour ahead, in a process of its own,
// takes pump 7 from a weaker commander (strength 50 over 1), then exits. The
// bridge orders commands by reception: the weaker commander, which repeats
// its command as a supervisor does, has the pump again within the departed
// commander's lease, and the pump is not held on. (Ordered by source
// timestamp, every later sample would be older than the departed one's and
// dropped: the pump would stay on, commanded by a process that is gone.)
TEST_F(CarelessClientTest, CommanderWithItsClockAnHourAheadLosesThePumpWhenItsProcessExits) {
  ASSERT_NO_FATAL_FAILURE(start_bridge());
  constexpr unsigned kMac = 7;
  constexpr Duration kLease = seconds(2);
  const std::string weak_issuer = "e2e weak";
  dds::Writer<dnbridge_PumpCommand> weak(
      supervisor_, command_topic_,
      dds::command_writer_qos(dds::rack_partitions(kRack), 1, seconds(1)));
  ASSERT_TRUE(writer_matched(weak));
  const auto off = pump_command(kMac, false, true, 123, weak_issuer);
  ASSERT_TRUE(weak.write(*off));
  ASSERT_TRUE(pumps_.until([&] { return echoes(kMac, false, true, 123, weak_issuer); }));

  const auto spawned = SteadyClock::now();
  auto& ahead = careless({"ahead", std::to_string(kMac), "50", "2000", "3600", "careless ahead"});
  ASSERT_EQ(ahead.read_line(milliseconds(15000)), "written");
  ASSERT_TRUE(pumps_.until([&] { return echoes(kMac, true, true, 4000, "careless ahead"); }))
      << "the stronger commander's command was not applied";
  report("careless commander spawned -> its command (stamped now + 3600 s) applied",
         ms_since(spawned));

  ASSERT_TRUE(ahead.send_line("exit"));
  ASSERT_EQ(ahead.wait_for(milliseconds(5000)), 0) << "the careless commander did not exit";
  const auto exited = SteadyClock::now();
  const bool taken_back = pumps_.until(
      [&] {
        if (echoes(kMac, false, true, 123, weak_issuer)) return true;
        EXPECT_TRUE(weak.write(*off));
        return false;
      },
      kLease, milliseconds(100));
  const auto* now_state = pumps_.latest(pump_mac(kMac));
  ASSERT_TRUE(taken_back) << "2 s after the commander an hour ahead exited, pump " << kMac
                          << " is commanded by \"" << dds::view(now_state->commanded_by)
                          << "\", pump_on " << now_state->pump_on << ", idle "
                          << now_state->outputs_idle;
  report("commander an hour ahead exited -> weaker commander's command applied", ms_since(exited));
  EXPECT_FALSE(pumps_.latest(pump_mac(kMac))->pump_on);
}

// 2. A client writes 300 requests under distinct txids and never unregisters
// them, and stays: the bridge's request reader holds 300 instances of it.
// Before eeaf5de the reader's limit was 256 instances; the 257th was refused,
// and Cyclone's delivery in the bridge's process, shared by every reader,
// waited for it, commands included. Now this client's command and Get are
// each served within 1 s.
TEST_F(CarelessClientTest, RequesterThatNeverUnregistersDelaysNeitherCommandsNorOtherRequests) {
  ASSERT_NO_FATAL_FAILURE(start_bridge());
  dds::Writer<dnbridge_PumpCommand> commander(
      supervisor_, command_topic_,
      dds::command_writer_qos(dds::rack_partitions(kRack), 10, seconds(1)));
  dds::Writer<dnbridge_ExplicitRequest> requests(
      supervisor_, request_topic_, dds::request_writer_qos(dds::rack_partitions(kRack)));
  Subscription<dnbridge_ExplicitReply> replies(supervisor_, reply_topic_,
                                               dds::reply_reader_qos(dds::rack_partitions(kRack)));
  ASSERT_TRUE(writer_matched(commander));
  ASSERT_TRUE(writer_matched(requests));
  ASSERT_TRUE(replies.matched(1));

  constexpr std::uint32_t kCareless = 300;
  const std::string careless_requester = "careless@" + std::to_string(getpid());
  auto& client = careless({"requests", careless_requester, std::to_string(kCareless)});
  const auto written = client.read_line(milliseconds(20000));
  ASSERT_TRUE(written.has_value()) << "the careless client did not write its requests";
  EXPECT_EQ(*written, "written 300 acked")
      << "the bridge did not acknowledge every request of the careless client";
  // Every one of them answered (8 executed, the others refused for the
  // requester's limit): the bridge has taken them all.
  const auto answered_all = replies.until(
      [&] { return answered(replies, careless_requester, 1, kCareless).size() == kCareless; });
  EXPECT_TRUE(answered_all) << answered(replies, careless_requester, 1, kCareless).size()
                            << " of the careless client's " << kCareless << " requests answered";

  const auto sent = SteadyClock::now();
  ASSERT_TRUE(commander.write(*pump_command(5, true, false, 2500, "e2e")));
  const bool applied =
      pumps_.until([&] { return echoes(5, true, false, 2500, "e2e"); }, seconds(1));
  EXPECT_TRUE(applied) << "the command was not applied within 1 s";
  if (applied) report("command written -> applied (300 instances held)", ms_since(sent));

  const auto get = get_round_trip(requests, replies, 1, seconds(1));
  EXPECT_TRUE(get.has_value()) << "the Get was not answered within 1 s";
  if (get) report("Get written -> reply (300 instances held)", *get);
  ASSERT_TRUE(careless_->running());
}

// 3. A client whose ExplicitReply reader is never taken from, with the reply
// QoS of before eeaf5de (keep-all, at most 4 samples per instance): after 4
// replies of the transaction it repeats, the reader rejects the next, and
// Cyclone's delivery in that client's process waits for it, for good. That
// process then acknowledges nothing, on any topic: the bridge's reply writer
// and its state writers have a reader that holds what they wrote. Readers
// that join late (transient-local, as a supervisor or dnbctl started now)
// make the bridge's writers resend what the stalled reader holds; with a
// keep-all reply writer and Cyclone's adaptive high-water mark, from then
// on every reply write waited and failed, for everyone. The client goes on
// with 600 Gets. Every node stays online throughout, no poll
// times out or is retried, every PortStatus says 8 nodes online and a longest
// loop pass of at most 5 ms (PortStatus.loop_longest_pass_ms; it leaves out
// the frames handled while the loop waits, hence the poll counters too), the
// early and the late NodeStatus readers get every node's status every
// period, and this client's own Get is answered within 1 s, to its early
// and its late reply reader.
// A pass's length is wall time: on a loaded machine it also counts the time
// other processes held the CPU (passes of under 1 ms of the port thread's own
// CPU time were seen at 7.8 ms, preempted). The bridge's port thread runs under
// SCHED_FIFO here, so that no other thread preempts it and what is measured is the
// bridge's own work and any wait of its port thread for DDS.
TEST_F(CarelessClientTest, ReplyReaderThatNeverTakesCostsNoPollAndNoNode) {
  ASSERT_NO_FATAL_FAILURE(start_bridge());
  ASSERT_TRUE(thread_to_fifo(bridge_->child().pid(), "port A"))
      << "the bridge's thread \"port A\" could not be put under SCHED_FIFO (CAP_SYS_NICE is "
         "needed)";
  EXPECT_TRUE(ports_.matched(1)) << "no PortStatus from the bridge";
  dds::Writer<dnbridge_ExplicitRequest> requests(
      supervisor_, request_topic_, dds::request_writer_qos(dds::rack_partitions(kRack)));
  Subscription<dnbridge_ExplicitReply> replies(supervisor_, reply_topic_,
                                               dds::reply_reader_qos(dds::rack_partitions(kRack)));
  ASSERT_TRUE(writer_matched(requests));
  ASSERT_TRUE(replies.matched(1));
  // The nodes' counters before: a node that left ONLINE and came back in
  // between two samples still counts a reconnection, and a poll answered
  // late (a port thread held up while the answer waited) a timeout, retry
  // or error.
  Watch watch(supervisor_);
  watch.add(nodes_);
  watch.add(ports_);
  watch.add(replies);
  const auto poll_trouble = [](const dnbridge_NodeCounters& c) {
    return c.poll_timeouts + c.poll_retries + c.poll_errors;
  };
  std::vector<std::uint64_t> reconnects(kPumps + 1, 0);
  std::vector<std::uint64_t> troubles(kPumps + 1, 0);
  ASSERT_TRUE(watch.until(
      [&] {
        for (unsigned mac = 1; mac <= kPumps; ++mac) {
          const auto* n = nodes_.latest(pump_mac(mac));
          if (!n || n->state != dnbridge_NODE_ONLINE) return false;
          reconnects[mac] = n->counters.reconnects;
          troubles[mac] = poll_trouble(n->counters);
        }
        return true;
      },
      kEventTimeout));
  const std::size_t nodes_from = nodes_.history().size();
  const std::size_t ports_from = ports_.history().size();

  constexpr std::uint32_t kRepeats = 20;
  constexpr std::uint32_t kGets = 600;
  const std::string careless_requester = "careless@" + std::to_string(getpid());
  const auto started = SteadyClock::now();
  auto& client = careless(
      {"stall-replies", careless_requester, std::to_string(kRepeats), std::to_string(kGets)});
  // A line from the client, taking what arrives meanwhile.
  const auto line_from_client = [&](Duration timeout) {
    std::optional<std::string> line;
    (void)watch.until(
        [&] {
          line = client.read_line(milliseconds(0));
          return line.has_value();
        },
        timeout);
    return line;
  };
  const auto stalled = line_from_client(seconds(30));
  ASSERT_TRUE(stalled.has_value()) << "the careless client did not start";
  ASSERT_EQ(stalled->rfind("stalled after ", 0), 0u) << *stalled;
  report("careless client started -> its reply reader rejected a reply", ms_since(started));
  // Late joiners, as a supervisor or dnbctl started now: readers of
  // NodeStatus and ExplicitReply (both transient-local) that ask the
  // bridge's writers for what they hold, samples the stalled client never
  // acknowledged. Those writers resend them: from then on, with the stalled
  // client still matched, they count as writers that are resending data.
  Subscription<dnbridge_NodeStatus> late_nodes(supervisor_, node_topic_, dds::state_reader_qos());
  Subscription<dnbridge_ExplicitReply> late_replies(
      supervisor_, reply_topic_, dds::reply_reader_qos(dds::rack_partitions(kRack)));
  ASSERT_TRUE(late_nodes.matched(1));
  ASSERT_TRUE(late_replies.matched(1));
  watch.add(late_nodes);
  watch.add(late_replies);
  ASSERT_TRUE(watch.until(
      [&] {
        for (unsigned mac = 1; mac <= kPumps; ++mac) {
          if (!late_nodes.latest(pump_mac(mac))) return false;
        }
        return late_replies.latest([](const auto&) { return true; }) != nullptr;
      },
      kEventTimeout))
      << "a late reader did not get the bridge's last NodeStatus and replies";
  ASSERT_TRUE(client.send_line("gets"));
  const auto sent = line_from_client(seconds(30));
  ASSERT_TRUE(sent.has_value()) << "the careless client did not write its Gets";
  report("careless client started -> its Gets written", ms_since(started));
  std::printf("[ measured ] careless client: %s; %s (writes ok, failed)\n", stalled->c_str(),
              sent->c_str());
  // The run goes on for three more status periods (1 s), replies still
  // coming: three more NodeStatus of every node, three more PortStatus.
  const std::size_t nodes_at_sent = nodes_.history().size();
  const std::size_t late_nodes_at_sent = late_nodes.history().size();
  const std::size_t ports_at_sent = ports_.history().size();
  const auto three_of_every_node = [](const Subscription<dnbridge_NodeStatus>& s,
                                      std::size_t from) {
    std::vector<unsigned> node_samples(kPumps + 1, 0);
    for (std::size_t i = from; i < s.history().size(); ++i) {
      const auto& n = s.history()[i].sample;
      if (n.valid_data() && n->mac <= kPumps) ++node_samples[n->mac];
    }
    return std::all_of(node_samples.begin() + 1, node_samples.end(),
                       [](unsigned c) { return c >= 3; });
  };
  const auto three_more = [&] {
    return three_of_every_node(nodes_, nodes_at_sent) &&
           three_of_every_node(late_nodes, late_nodes_at_sent) &&
           ports_.history().size() >= ports_at_sent + 3;
  };
  EXPECT_TRUE(watch.until(three_more, seconds(15)))
      << "not three status periods' NodeStatus and PortStatus within 15 s: "
      << nodes_.history().size() - nodes_at_sent << " NodeStatus, "
      << late_nodes.history().size() - late_nodes_at_sent << " NodeStatus to the late reader, "
      << ports_.history().size() - ports_at_sent << " PortStatus";
  const double run_ms = ms_since(started);
  report("run (careless client started -> three status periods after its writes)", run_ms);

  // Nodes: every NodeStatus of the run says online; no reconnection, no poll
  // timed out, retried or answered wrong.
  for (std::size_t i = nodes_from; i < nodes_.history().size(); ++i) {
    const auto& n = nodes_.history()[i].sample;
    if (!n.valid_data()) continue;
    EXPECT_EQ(n->state, dnbridge_NODE_ONLINE)
        << "node " << unsigned{n->mac} << " left ONLINE: " << dds::view(n->reason);
  }
  for (unsigned mac = 1; mac <= kPumps; ++mac) {
    const auto& counters = nodes_.latest(pump_mac(mac))->counters;
    EXPECT_EQ(counters.reconnects, reconnects[mac]) << "node " << mac;
    EXPECT_EQ(poll_trouble(counters), troubles[mac])
        << "node " << mac << ": poll timeouts " << counters.poll_timeouts << ", retries "
        << counters.poll_retries << ", errors " << counters.poll_errors;
  }
  // The port: a PortStatus every status period (1 s), 8 nodes online, the
  // loop's longest pass at most 5 ms.
  float longest = 0;
  std::size_t port_samples = 0;
  for (std::size_t i = ports_from; i < ports_.history().size(); ++i) {
    const auto& p = ports_.history()[i].sample;
    if (!p.valid_data()) continue;
    ++port_samples;
    longest = std::max(longest, p->loop_longest_pass_ms);
    EXPECT_EQ(p->nodes_online, kPumps);
    EXPECT_LE(p->loop_longest_pass_ms, 5.0f);
  }
  EXPECT_GE(static_cast<double>(port_samples), run_ms / 1000.0 - 1.0)
      << "PortStatus came less often than every status period";
  report("longest port loop pass during the run", longest);

  const auto answered_gets = answered(replies, careless_requester, 2, kGets + 1).size();
  const auto* last = ports_.latest([](const auto&) { return true; });
  std::printf("[ measured ] of the careless client's %u Gets %zu answered\n", kGets, answered_gets);
  RecordProperty("careless Gets answered", static_cast<int>(answered_gets));
  if (last) {
    std::printf(
        "[ measured ] PortStatus: replies undelivered %llu, refused for limits %llu, "
        "outstanding %u, retained %u; %zu samples in the run\n",
        static_cast<unsigned long long>(last->replies_undelivered),
        static_cast<unsigned long long>(last->explicit_refused_for_limits),
        last->explicit_outstanding, last->explicit_retained, port_samples);
    RecordProperty("replies undelivered", std::to_string(last->replies_undelivered));
  }
  ASSERT_TRUE(client.send_line("status"));
  const auto rejected = line_from_client(kEventTimeout);
  ASSERT_TRUE(rejected.has_value());
  std::printf("[ measured ] careless client's reply reader: %s\n", rejected->c_str());

  // This client is still served, its early reader and its late one alike.
  const auto get = get_round_trip(requests, replies, 1, seconds(1));
  EXPECT_TRUE(get.has_value()) << "the well-behaved Get was not answered within 1 s";
  EXPECT_TRUE(late_replies.until(
      [&] {
        return late_replies.latest([&](const dnbridge_ExplicitReply& r) {
          return r.txid == 1 && dds::view(r.requester) == requester_;
        }) != nullptr;
      },
      seconds(1)))
      << "the late reply reader did not get the well-behaved Get's reply";
  if (get) report("well-behaved Get written -> reply, the careless reader stalled", *get);
}

// 4. 100 000 requests in 5 rounds of 20 000, well-behaved (each request's
// instance unregistered once its reply came, at most 128 outstanding): 49 of
// every 50 to MAC 40, which is not in the scan list (refused at once), one to
// a node of the rack (a Get executed on the bus). Whatever the bridge keeps
// per transaction it lets go: its resident set after the last round is within
// 4 MiB of that after the first.
TEST_F(CarelessClientTest, HundredThousandRequestsLeaveTheBridgeResidentSetFlat) {
  // Built with AddressSanitizer, the bridge would hold what it frees in a
  // quarantine of up to 256 MB: without one its resident set means the same.
  ASSERT_NO_FATAL_FAILURE(start_bridge({.env = {"ASAN_OPTIONS=quarantine_size_mb=0"}}));
  dds::Writer<dnbridge_ExplicitRequest> requests(
      supervisor_, request_topic_, dds::request_writer_qos(dds::rack_partitions(kRack)));
  dds::Reader<dnbridge_ExplicitReply> replies(supervisor_, reply_topic_,
                                              dds::reply_reader_qos(dds::rack_partitions(kRack)));
  ASSERT_TRUE(writer_matched(requests));
  {
    // Until the bridge's reply writer is matched too.
    ASSERT_TRUE(replies.set_status_mask(DDS_SUBSCRIPTION_MATCHED_STATUS).ok());
    const auto deadline = SteadyClock::now() + kEventTimeout;
    while (replies.matched_publications().value_or(0) < 1 && SteadyClock::now() < deadline) {
      (void)dds::testing::wait_for(supervisor_, replies, deadline - SteadyClock::now());
    }
    ASSERT_EQ(replies.matched_publications().value_or(0), 1u);
  }
  dds::ReadCondition fresh(replies,
                           DDS_NOT_READ_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ANY_INSTANCE_STATE);
  dds::WaitSet waitset(supervisor_);
  waitset.attach(fresh, 1);
  dds::TakeBuffer<dnbridge_ExplicitReply> taken(64);

  constexpr std::uint32_t kRounds = 5;
  constexpr std::uint32_t kPerRound = 20000;
  constexpr std::size_t kWindow = 128;
  constexpr unsigned kNotInScanList = 40;
  std::vector<bool> outstanding(kRounds * kPerRound + 1, false);
  std::vector<long> rss_kib;
  std::uint64_t executed_ok = 0;
  std::uint32_t txid = 0;
  const auto test_started = SteadyClock::now();
  for (std::uint32_t round = 0; round < kRounds; ++round) {
    const auto round_started = SteadyClock::now();
    std::size_t in_flight = 0;
    std::uint32_t sent = 0;
    while (sent < kPerRound || in_flight > 0) {
      while (sent < kPerRound && in_flight < kWindow) {
        ++txid;
        const unsigned mac = txid % 50 == 0 ? 1 + (txid / 50) % kPumps : kNotInScanList;
        const auto request = get_vendor(txid, mac);
        ASSERT_TRUE(again_while_full([&] { return requests.write(*request); })) << txid;
        outstanding[txid] = true;
        ++in_flight;
        ++sent;
      }
      auto woken = waitset.wait(kEventTimeout);
      ASSERT_TRUE(woken.ok() && !woken->empty())
          << "no reply for 5 s; " << in_flight << " outstanding in round " << round + 1;
      for (;;) {
        auto n = replies.take(taken);
        ASSERT_TRUE(n.ok());
        for (std::size_t i = 0; i < *n; ++i) {
          const auto& r = taken.data(i);
          if (!taken.info(i).valid_data() || dds::view(r.requester) != requester_ ||
              r.txid >= outstanding.size() || !outstanding[r.txid]) {
            continue;
          }
          outstanding[r.txid] = false;
          --in_flight;
          if (r.txid % 50 == 0 && r.status == kStatusSuccess) ++executed_ok;
          // Done with the transaction: its instance goes.
          dds::Owned<dnbridge_ExplicitRequest> key;
          dds::set_string(key->requester, requester_);
          key->txid = r.txid;
          ASSERT_TRUE(again_while_full([&] { return requests.unregister_instance(*key); }));
        }
        if (*n < taken.capacity()) break;
      }
    }
    rss_kib.push_back(bridge_->rss_kib());
    std::printf("[ measured ] round %u: %u requests in %.0f ms; bridge VmRSS %ld KiB\n", round + 1,
                kPerRound, ms_since(round_started), rss_kib.back());
  }
  report("100 000 requests, answered and unregistered", ms_since(test_started));
  ports_.take_all();
  if (const auto* port = ports_.latest([](const auto&) { return true; })) {
    std::printf(
        "[ measured ] last PortStatus: explicit outstanding %u, retained %u, refused for limits "
        "%llu, replies undelivered %llu\n",
        port->explicit_outstanding, port->explicit_retained,
        static_cast<unsigned long long>(port->explicit_refused_for_limits),
        static_cast<unsigned long long>(port->replies_undelivered));
  }
  std::printf("[ measured ] Gets executed on the bus with success: %llu of %u\n",
              static_cast<unsigned long long>(executed_ok), kRounds * kPerRound / 50);
  RecordProperty("bridge VmRSS first round KiB", std::to_string(rss_kib.front()));
  RecordProperty("bridge VmRSS last round KiB", std::to_string(rss_kib.back()));
  ASSERT_GT(rss_kib.front(), 0);
  EXPECT_LE(rss_kib.back() - rss_kib.front(), 4 * 1024)
      << "the bridge grew by " << rss_kib.back() - rss_kib.front() << " KiB";
  EXPECT_GT(executed_ok, 0u);
}

// 5. Cyclone DDS 0.10.2, pinned. One client process, three PumpCommand
// writers in one participant, each with the documented command writer QoS
// (the same strength, the same 2 s automatic-liveliness lease), writer N
// commanding pump N; all three live. Writers 1 and 2 are deleted back to
// back, writer 3 is not, and its process lives on.
//
// What happens: pump 3 goes idle too ("idle: no live commander"), at once
// (well within the lease), while its writer is alive and silent. It is not
// the bridge: this process's own PumpCommand reader, with the bridge's QoS,
// sees pump 3's instance go NOT_ALIVE_NO_WRITERS from writer 3. Observed while
// pinning, not asserted (it lasts only until the participant is seen alive
// again): liveliness_changed of that reader went from alive 3 to alive 0, every
// remaining writer of the participant not alive; deleting writer 1 alone did
// the same to pumps 2 and 3; deleting writer 3 alone left writers 1 and 2
// alive (alive 3 -> 2). As read in the 0.10.2 source
// (ddsi_proxy_participant_remove_pwr_lease_locked): when the deleted writer's
// lease was the participant's shortest, the replacement lease expires at
// now + (new shortest - old shortest), which is now when the leases are
// equal, so the remote participant's automatic liveliness expires on the
// spot. The writer's next sample makes it alive again: a commander that
// rewrites its command (as the README asks of commanders) has its pump back
// at its next write, which this test checks too.
//
// If this test fails, Cyclone (or the QoS) changed: the third pump is no
// longer idled, and the comment above and the README's advice can say so.
TEST_F(CarelessClientTest, DeletingTwoWritersOfAParticipantIdlesThePumpOfItsThirdLiveWriter) {
  ASSERT_NO_FATAL_FAILURE(start_bridge());
  Subscription<dnbridge_PumpCommand> commands(supervisor_, command_topic_,
                                              dds::command_reader_qos(dds::rack_partitions(kRack)));
  // The bridge's reader and this one.
  auto& client = careless({"three-writers", "10", "2000", "2"});
  ASSERT_EQ(client.read_line(milliseconds(15000)), "written");
  ASSERT_TRUE(pumps_.until([&] {
    return echoes(1, true, false, 100, "writer-1") && echoes(2, true, false, 200, "writer-2") &&
           echoes(3, true, false, 300, "writer-3");
  }));
  ASSERT_TRUE(commands.until([&] { return commands.history().size() >= 3; }));
  dds_instance_handle_t writer3 = 0;
  for (const auto& r : commands.history()) {
    if (r.sample.valid_data() && r.sample->mac == 3) writer3 = r.sample.info().publication_handle();
  }
  ASSERT_NE(writer3, 0u);
  const std::size_t commands_before = commands.history().size();

  ASSERT_TRUE(client.send_line("delete 1 2"));
  ASSERT_EQ(client.read_line(milliseconds(5000)), "deleted");
  const auto deleted = SteadyClock::now();
  ASSERT_TRUE(pumps_.until([&] { return idle(1) && idle(2); }))
      << "pumps 1 and 2 still commanded after their writers were deleted";
  report("writers 1 and 2 deleted -> pumps 1 and 2 idle", ms_since(deleted));

  // The pin: pump 3 idle as well, within its writer's lease.
  ASSERT_TRUE(pumps_.until([&] { return idle(3); }, seconds(2)))
      << "pump 3 stayed commanded by its live writer: Cyclone no longer idles it";
  report("writers 1 and 2 deleted -> pump 3 (writer 3 live) idle", ms_since(deleted));
  EXPECT_EQ(dds::view(pumps_.latest(pump_mac(3))->idle_reason), "idle: no live commander");
  // This process's reader saw the same: writer 3 no longer a live writer of
  // pump 3's instance.
  ASSERT_TRUE(commands.until([&] {
    for (std::size_t i = commands_before; i < commands.history().size(); ++i) {
      const auto& r = commands.history()[i].sample;
      if (r->mac == 3 && r.info().instance_state() == dds::InstanceState::kNotAliveNoWriters &&
          r.info().publication_handle() == writer3) {
        return true;
      }
    }
    return false;
  })) << "this process's reader still has pump 3's instance alive";
  ASSERT_TRUE(careless_->running());

  // Writer 3's next command takes pump 3 again.
  ASSERT_TRUE(client.send_line("write 3"));
  ASSERT_EQ(client.read_line(milliseconds(5000)), "written");
  ASSERT_TRUE(pumps_.until([&] { return echoes(3, true, false, 300, "writer-3"); }))
      << "writer 3's new command was not applied";
  EXPECT_TRUE(idle(1));
  EXPECT_TRUE(idle(2));
}

// 6. A flood of commands from another process: Cyclone's receive thread there
// hands them to the bridge's listener while the bridge's input thread may be
// taking the ones the flood hold-off kept back. None is stranded in the
// reader: every pump ends with the last command written for it.
TEST_F(CarelessClientTest, AFloodFromAnotherProcessEndsWithEveryPumpsNewestCommand) {
  ASSERT_NO_FATAL_FAILURE(start_bridge());
  auto& client = careless({"flood", "flood", "10", "5000"});
  ASSERT_EQ(client.read_line(milliseconds(30000)), "written");
  ASSERT_TRUE(pumps_.until([&] {
    for (unsigned mac = 1; mac <= 4; ++mac) {
      if (!echoes(mac, true, true, static_cast<std::uint16_t>(4000 + mac), "flood")) return false;
    }
    return true;
  })) << "a pump did not end with its newest command";
  ASSERT_TRUE(careless_->running());
}

// 7. A reader that acknowledges nothing (a client process stopped with
// SIGSTOP, once it has a sample of the writer) while the state writers keep
// more unacknowledged data than Cyclone lets a keep-all writer keep (its
// high-water mark, 500 kB at most): 64 ports of 63 pumps, about 800 kB of
// PumpState. The port threads write state samples themselves (DdsPublisher),
// so no such write may wait, nor fail: each call returns within 50 ms (a
// write held back would take the QoS's max blocking time, and the next
// pump's the same), no write failed, and every sample reached this
// process's reader (Cyclone delivers to a reader in the writer's process
// only what it could write). The reader resumes, every instance is
// published again as the ports do each period, and every instance's newest
// sample is delivered.
TEST_F(CarelessClientTest, AStateReaderThatAcknowledgesNothingNeverHoldsThePortThreads) {
  constexpr unsigned kPorts = 64;
  constexpr unsigned kMacs = 63;
  daemon::DdsPublisher publisher(supervisor_, "stalled-rack", seconds(5), Logger{});
  auto& client = careless({"state-reader"});

  const auto port_name = [](unsigned p) { return "port-" + std::to_string(p); };
  // Every instance once, named `round` (padded: about 200 bytes a sample);
  // the longest call.
  const auto publish_all = [&](const std::string& round) {
    Duration longest{};
    rack::PumpView view;
    view.profile = rack::PumpProfile::kName;
    view.name = round + std::string(100, '.');
    for (unsigned p = 0; p < kPorts; ++p) {
      for (unsigned mac = 1; mac <= kMacs; ++mac) {
        view.mac = devicenet::MacId::from_bits(mac);
        const auto start = SteadyClock::now();
        publisher.node_state(port_name(p), view, port::steady_now());
        longest = std::max<Duration>(longest, SteadyClock::now() - start);
      }
    }
    return longest;
  };
  // Every instance's sample of round `round`, here.
  const auto every_instance = [&](std::string_view round) {
    return [&, round] {
      std::set<std::pair<std::string, unsigned>> seen;
      for (const auto& r : pumps_.history()) {
        if (r.sample.valid_data() && dds::view(r.sample->rack) == "stalled-rack" &&
            dds::view(r.sample->name).starts_with(round)) {
          seen.emplace(std::string(dds::view(r.sample->port)), r.sample->mac);
        }
      }
      return seen.size() == kPorts * kMacs;
    };
  };
  const auto as_ms = [](Duration d) {
    return std::chrono::duration<double, std::milli>(d).count();
  };

  // The client's reader has a sample: the writer has matched it.
  rack::PumpView first;
  first.profile = rack::PumpProfile::kName;
  first.mac = devicenet::MacId::from_bits(1);
  first.name = "first";
  const auto receiving = [&] {
    std::optional<std::string> line;
    const auto deadline = SteadyClock::now() + seconds(30);
    while (!line && SteadyClock::now() < deadline) {
      publisher.node_state(port_name(0), first, port::steady_now());
      line = client.read_line(milliseconds(100));
    }
    return line;
  };
  ASSERT_EQ(receiving(), std::optional<std::string>("receiving"))
      << "the client's state reader got no sample";

  ASSERT_EQ(kill(client.pid(), SIGSTOP), 0);
  const Duration stalled_longest = publish_all("stalled");
  ASSERT_EQ(kill(client.pid(), SIGCONT), 0);
  report("longest PumpState call, a reader stopped (4032 instances)", as_ms(stalled_longest));
  EXPECT_LT(stalled_longest, milliseconds(50));
  EXPECT_EQ(publisher.state_write_failures(), 0u);
  EXPECT_TRUE(pumps_.until(every_instance("stalled"), seconds(10)))
      << "a sample written while the reader was stopped did not reach this process's reader";

  publisher.flush(seconds(10));
  const Duration resumed_longest = publish_all("resumed");
  report("longest PumpState call, the reader resumed", as_ms(resumed_longest));
  EXPECT_LT(resumed_longest, milliseconds(50));
  const auto newest_everywhere = every_instance("resumed");
  EXPECT_TRUE(pumps_.until(newest_everywhere, seconds(10)))
      << "not every instance's newest sample was delivered after the reader resumed";
  ASSERT_TRUE(client.running());
}

}  // namespace
}  // namespace dnbridge::e2e
