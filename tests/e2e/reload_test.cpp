// A configuration read again while the bridge runs, end to end: the bridge
// of the simulated rack in this process, its "file" a text the test edits,
// a supervisor on DDS. A file with problems changes nothing and says where;
// a good one changes only what differs (an added node comes online, a
// removed one's instances are disposed, a changed one is configured again,
// the untouched ones never leave online) and names what needs a restart;
// a ReloadRequest on DDS gets its ReloadReply.
#include <fmt/format.h>

#include "bridge_fixture.hpp"

namespace dnbridge::e2e {
namespace {

constexpr const char* kFile = "rack-reload.toml";

class ReloadTest : public BridgeTest {
 protected:
  // The embedded default on this process's domain, a simulated CDN127 at
  // MAC 9 that it does not configure (yet).
  ReloadTest() : text_(daemon::embedded_default_config_text()) {
    replace("domain = 0", fmt::format("domain = {}", test_domain()));
    replace("bitrate = 500000\n", "bitrate = 500000\nsimulated_unconfigured = [9]\n");
  }

  void replace(std::string_view from, const std::string& to) {
    const auto at = text_.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text_.replace(at, from.size(), to);
  }
  daemon::DaemonConfig parse() const { return daemon::parse_config(text_, kFile); }
  daemon::ReloadSource source() {
    return {[this] { return parse(); }, {}};
  }
  void start() { ASSERT_NO_FATAL_FAILURE(start_online(parse(), source())); }

  static bool has_line(const std::vector<std::string>& lines, std::string_view text) {
    return std::any_of(lines.begin(), lines.end(),
                       [&](const std::string& l) { return l.find(text) != std::string::npos; });
  }
  static std::string joined(const daemon::ReloadReport& r) {
    std::string s = r.message;
    for (const auto* list : {&r.applied, &r.needs_restart, &r.problems}) {
      for (const auto& l : *list) s += "\n  " + l;
    }
    return s;
  }

  std::string text_;
};

TEST_F(ReloadTest, AFileWithProblemsChangesNothingAndSaysWhere) {
  ASSERT_NO_FATAL_FAILURE(start());
  const std::string good = text_;
  // Line and column of the mistake: node 8 at MAC 99.
  ASSERT_NO_FATAL_FAILURE(replace("mac = 8\n", "mac = 99\n"));
  ASSERT_NO_FATAL_FAILURE(replace("name = \"pump-1\"", "name = \"pump-one\""));
  const auto line =
      1 + std::count(text_.begin(),
                     text_.begin() + static_cast<std::ptrdiff_t>(text_.find("mac = 99")), '\n');
  const auto r = bridge_->reload();
  EXPECT_EQ(r.status, daemon::ReloadStatus::kRefused) << joined(r);
  EXPECT_TRUE(r.applied.empty()) << joined(r);
  ASSERT_FALSE(r.problems.empty());
  EXPECT_TRUE(has_line(r.problems, fmt::format("{}:{}:", kFile, line))) << joined(r);
  EXPECT_NE(r.message.find("nothing changed"), std::string::npos) << r.message;
  // Nothing changed: the node is there, its name too.
  EXPECT_EQ(bridge_->port(kPort)->nodes_configured(), kPumps);
  EXPECT_TRUE(bridge_->port(kPort)->has_node(*devicenet::MacId::from(8)));
  EXPECT_EQ(bridge_->config().ports.at(0).nodes.at(0).pump.node.name, "pump-1");
  ASSERT_TRUE(pumps_.until([&] { return pumps_.history().size() > 2 * kPumps + 8; }));
  EXPECT_EQ(dds::view(pumps_.latest(pump_mac(1))->name), "pump-1");
  text_ = good;
  const auto again = bridge_->reload();
  EXPECT_EQ(again.status, daemon::ReloadStatus::kApplied) << joined(again);
  EXPECT_TRUE(again.applied.empty()) << joined(again);
}

TEST_F(ReloadTest, OnlyWhatDiffersIsAppliedAndWhatNeedsARestartIsNamed) {
  ASSERT_NO_FATAL_FAILURE(start());
  // Node 4 out (from the middle of the scan list), node 9 in (the simulated
  // device stays), node 2 with another fault action, node 3 renamed, the
  // bit rate changed (not live).
  const auto at4 = text_.find("  [[port.node]]\n  mac = 4\n");
  ASSERT_NE(at4, std::string::npos);
  text_.erase(at4, text_.find("  [[port.node]]", at4 + 4) - at4);
  ASSERT_NO_FATAL_FAILURE(replace("simulated_unconfigured = [9]\n", ""));
  text_ += "\n  [[port.node]]\n  mac = 9\n  name = \"pump-9\"\n";
  ASSERT_NO_FATAL_FAILURE(
      replace("name = \"pump-2\"\n", "name = \"pump-2\"\n  pump_on_fault = \"hold\"\n"));
  ASSERT_NO_FATAL_FAILURE(replace("name = \"pump-3\"", "name = \"Pumpe drei\""));
  ASSERT_NO_FATAL_FAILURE(replace("bitrate = 500000", "bitrate = 250000"));
  ASSERT_TRUE(nodes_.until([&] { return nodes_.latest(pump_mac(1)) != nullptr; }));
  const auto* before = nodes_.latest(pump_mac(1));
  const auto reconnects_before = before->counters.reconnects;
  const auto timeouts_before = before->counters.poll_timeouts;
  const auto polls_before = before->counters.polls;
  const auto reload_wall = wall_now();

  const auto r = bridge_->reload();
  EXPECT_EQ(r.status, daemon::ReloadStatus::kApplied) << joined(r);
  EXPECT_EQ(r.file, kFile);
  EXPECT_TRUE(has_line(r.applied, "port A: node 9 added")) << joined(r);
  EXPECT_TRUE(has_line(r.applied, "port A: node 4 removed")) << joined(r);
  EXPECT_TRUE(has_line(r.applied, "port A: node 2 configured again")) << joined(r);
  EXPECT_TRUE(has_line(r.applied, "port A: node 3 name or policies changed")) << joined(r);
  EXPECT_EQ(r.applied.size(), 4u) << joined(r);
  ASSERT_EQ(r.needs_restart.size(), 1u) << joined(r);
  EXPECT_EQ(r.needs_restart[0], "port A: bitrate 500000 in force, 250000 in the file");
  EXPECT_TRUE(r.problems.empty()) << joined(r);

  // On DDS: 9 online, 4 disposed, 2 back online and idle, 3 renamed.
  const auto disposed = [&](unsigned mac) {
    for (const auto& s : pumps_.history()) {
      if (s.sample->mac == mac &&
          s.sample.info().instance_state() == dds::InstanceState::kNotAliveDisposed) {
        return true;
      }
    }
    return false;
  };
  ASSERT_TRUE(pumps_.until(
      [&] {
        const auto* nine = pumps_.latest(pump_mac(9));
        const auto* two = pumps_.latest(pump_mac(2));
        const auto* three = pumps_.latest(pump_mac(3));
        return nine && nine->online && disposed(4) && two && two->online &&
               dds::view(two->idle_reason).find("after a reload") != std::string_view::npos &&
               three && dds::view(three->name) == "Pumpe drei";
      },
      seconds(10)));
  EXPECT_EQ(bridge_->port(kPort)->nodes_configured(), kPumps);
  EXPECT_FALSE(bridge_->port(kPort)->has_node(*devicenet::MacId::from(4)));
  // Node 1 never left online, nor did it reconnect.
  for (const auto& s : pumps_.history()) {
    if (s.sample.valid_data() && s.sample->mac == 1 && s.at >= reload_wall) {
      EXPECT_TRUE(s.sample->online);
    }
  }
  ASSERT_TRUE(nodes_.until([&] {
    const auto* n = nodes_.latest(pump_mac(1));
    return n && n->counters.polls > polls_before + 10;
  }));
  EXPECT_EQ(nodes_.latest(pump_mac(1))->counters.reconnects, reconnects_before);
  EXPECT_EQ(nodes_.latest(pump_mac(1))->counters.poll_timeouts, timeouts_before);
  // The device at 2 has the new fault action.
  EXPECT_TRUE(on_port([](sim::SimBackend& b) {
    return slave(b, 2).device().device().e2().dop[0].fault_hold;  // DOP 1, Pump On
  }));

  // Read again unchanged: nothing to apply; the restart is still needed.
  const auto again = bridge_->reload();
  EXPECT_EQ(again.status, daemon::ReloadStatus::kApplied) << joined(again);
  EXPECT_TRUE(again.applied.empty()) << joined(again);
  EXPECT_EQ(again.needs_restart.size(), 1u) << joined(again);
}

TEST_F(ReloadTest, AReloadRequestOnDdsGetsItsReply) {
  ASSERT_NO_FATAL_FAILURE(start());
  dds::Topic<dnbridge_ReloadRequest> request_topic{supervisor_};
  dds::Topic<dnbridge_ReloadReply> reply_topic{supervisor_};
  dds::Writer<dnbridge_ReloadRequest> requests{
      supervisor_, request_topic, dds::request_writer_qos(dds::rack_partitions(kRack))};
  Subscription<dnbridge_ReloadReply> replies{supervisor_, reply_topic,
                                             dds::reply_reader_qos(dds::rack_partitions(kRack))};
  ASSERT_TRUE(writer_matched(requests));
  ASSERT_TRUE(replies.matched(1));
  ASSERT_NO_FATAL_FAILURE(replace("name = \"pump-4\"", "name = \"pump four\""));

  const auto ask = [&](std::uint32_t txid, const char* rack) {
    dds::Owned<dnbridge_ReloadRequest> s;
    dds::set_string(s->requester, requester_);
    s->txid = txid;
    dds::set_string(s->rack, rack);
    ASSERT_TRUE(requests.write(*s).ok());
  };
  const auto reply = [&](std::uint32_t txid) -> const dnbridge_ReloadReply* {
    return replies.latest([&](const dnbridge_ReloadReply& r) {
      return r.txid == txid && dds::view(r.requester) == requester_;
    });
  };
  ask(7, "another-rack");  // not this bridge's
  ask(8, kRack);
  ASSERT_TRUE(replies.until([&] { return reply(8) != nullptr; }));
  const auto* r = reply(8);
  EXPECT_EQ(r->status, dnbridge_RELOAD_APPLIED);
  EXPECT_EQ(dds::view(r->rack), kRack);
  EXPECT_EQ(dds::view(r->file), kFile);
  ASSERT_EQ(r->applied._length, 1u);
  EXPECT_NE(std::string_view(r->applied._buffer[0]).find("node 4 name or policies changed"),
            std::string_view::npos)
      << r->applied._buffer[0];
  EXPECT_EQ(reply(7), nullptr);
  // Written again (a client repeats until answered): the same reply, not a
  // second reload.
  const auto replies_of = [&](std::uint32_t txid) {
    return std::count_if(replies.history().begin(), replies.history().end(), [&](const auto& s) {
      return s.sample.valid_data() && s.sample->txid == txid;
    });
  };
  ask(8, kRack);
  ASSERT_TRUE(replies.until([&] { return replies_of(8) == 2; }));
  EXPECT_EQ(reply(8)->status, dnbridge_RELOAD_APPLIED);
  EXPECT_EQ(reply(8)->applied._length, 1u);
  EXPECT_EQ(log_.count(LogLevel::kInfo, fmt::format("reload asked by {} (txid 8)", requester_)),
            1u);
  ASSERT_TRUE(pumps_.until([&] {
    const auto* four = pumps_.latest(pump_mac(4));
    return four && dds::view(four->name) == "pump four";
  }));

  // A burst of requests: each answered once, by at most two reloads (one
  // may start at once; the rest wait for it and its hold-off, and share
  // the next).
  const auto reloads_before = log_.count(LogLevel::kInfo, "reload asked by");
  for (std::uint32_t txid = 100; txid < 120; ++txid) ask(txid, kRack);
  ASSERT_TRUE(replies.until(
      [&] {
        for (std::uint32_t txid = 100; txid < 120; ++txid) {
          if (replies_of(txid) == 0) return false;
        }
        return true;
      },
      seconds(10)));
  for (std::uint32_t txid = 100; txid < 120; ++txid) {
    EXPECT_EQ(replies_of(txid), 1) << txid;
    EXPECT_EQ(reply(txid)->status, dnbridge_RELOAD_APPLIED);
  }
  EXPECT_LE(log_.count(LogLevel::kInfo, "reload asked by") - reloads_before, 2u);
  EXPECT_TRUE(log_.contains(LogLevel::kInfo, "other request(s)"));

  // A file with problems: refused, with them.
  ASSERT_NO_FATAL_FAILURE(replace("poll_period_ms = 100", "poll_period_ms = -5"));
  ask(9, kRack);
  ASSERT_TRUE(replies.until([&] { return reply(9) != nullptr; }));
  EXPECT_EQ(reply(9)->status, dnbridge_RELOAD_REFUSED);
  EXPECT_GE(reply(9)->problems._length, 1u);
  EXPECT_EQ(reply(9)->applied._length, 0u);
}

TEST_F(BridgeTest, ABridgeOnItsEmbeddedDefaultHasNoFileToReadAgain) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  const auto r = bridge_->reload();
  EXPECT_EQ(r.status, daemon::ReloadStatus::kNoFile);
  EXPECT_NE(r.message.find("embedded default"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace dnbridge::e2e
