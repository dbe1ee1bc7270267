// SocketCanBackend's transmit back-pressure, error states and interface loss,
// on the host: the backend runs on a FakeIo whose "CAN socket" is one end of
// an AF_UNIX SOCK_SEQPACKET socketpair (so epoll readiness is real), whose
// clock is the test's, and whose calls fail on the Nth call as scripted.
#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/netlink.h>
#include <sys/socket.h>
#include <sys/timerfd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <deque>
#include <fstream>
#include <regex>
#include <vector>

#include "adapters/socketcan/socketcan_backend.hpp"

namespace dnbridge::socketcan {
namespace {

using port::BusState;

constexpr TimePoint kStart = TimePoint(seconds(1000));
// No test here needs more epoll_wait() calls than this; a backend that
// spins reaches it and fails instead of hanging.
constexpr int kMaxWaits = 1000;

class FakeIo final : public CanIo {
 public:
  // --- the script ---------------------------------------------------------
  LinkState link = LinkState::kUp;
  // What socket(AF_CAN) fails with: EAFNOSUPPORT on a kernel without
  // SocketCAN; 0: it works.
  int kernel_can_errno = 0;
  // The errno of the next write() / read() calls, one per call, front
  // first; 0 (or none left): the real call on the socketpair.
  std::deque<int> write_errors;
  std::deque<int> read_errors;
  bool controller = false;
  int controller_state = CAN_STATE_ERROR_ACTIVE;
  std::uint32_t restart_ms = 100;
  int restart_errno = 0;  // do_restart() fails with it when not 0

  // --- what happened ------------------------------------------------------
  TimePoint clock = kStart;
  std::vector<TimePoint> write_calls;  // every write(), failed or not
  int eagains = 0;
  int read_calls = 0;
  std::vector<TimePoint> link_checks;
  std::vector<TimePoint> opens;
  std::vector<TimePoint> restarts;
  int waits = 0;  // epoll_wait() calls

  // The test's end of the current socket.
  FileDescriptor peer;

  std::error_code can_support() override {
    return kernel_can_errno ? errno_code(kernel_can_errno) : std::error_code();
  }
  LinkState link_state(const std::string&) override {
    link_checks.push_back(clock);
    return link;
  }

  Result<CanSocket> open(const std::string&, const SocketOptions&) override {
    opens.push_back(clock);
    int fds[2];
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, fds) < 0) {
      return errno_code();
    }
    // The smallest send buffer: a handful of frames fill it, and EAGAIN and
    // EPOLLOUT then come from the kernel, consistent with each other.
    const int one = 1;
    (void)::setsockopt(fds[0], SOL_SOCKET, SO_SNDBUF, &one, sizeof one);
    peer.reset(fds[1]);
    return CanSocket(FileDescriptor(fds[0]));
  }
  Status write(CanSocket& socket, const can::CanFrame& frame) override {
    write_calls.push_back(clock);
    const int e = next(write_errors);
    if (e != 0) return errno_code(e);
    auto s = socket.write(frame);
    if (!s && is(s.error(), EAGAIN)) ++eagains;
    return s;
  }
  Result<Received> read(CanSocket& socket) override {
    ++read_calls;
    const int e = next(read_errors);
    if (e != 0) return errno_code(e);
    return socket.read();
  }
  std::error_code take_error(CanSocket& socket) override { return socket.take_error(); }

  bool has_controller(const std::string&) override { return controller; }
  int get_state(const std::string&, int* state) override {
    *state = controller_state;
    return 0;
  }
  int get_berr_counter(const std::string&, can_berr_counter* c) override {
    c->txerr = 0;
    c->rxerr = 0;
    return 0;
  }
  int get_bittiming(const std::string&, can_bittiming* t) override {
    t->bitrate = 500000;
    return 0;
  }
  int get_restart_ms(const std::string&, std::uint32_t* ms) override {
    *ms = restart_ms;
    return 0;
  }
  int do_restart(const std::string&) override {
    restarts.push_back(clock);
    if (restart_errno == 0) return 0;
    errno = restart_errno;
    return -1;
  }

  TimePoint now() override { return clock; }
  void set_timer(int fd, TimePoint at) override {
    timer_fd_ = fd;
    armed_ = at;
  }
  // What is ready now; when nothing is and the caller would block, time
  // jumps to the armed timer, which then fires (the real timerfd is made
  // to expire, so the backend reads it as it would).
  int wait(int epoll_fd, epoll_event* events, int max_events, int timeout_ms) override {
    if (++waits > kMaxWaits) {
      ADD_FAILURE() << "the backend spins: " << waits << " epoll_wait() calls";
      errno = EINVAL;
      return -1;
    }
    const int n = ::epoll_wait(epoll_fd, events, max_events, 0);
    if (n != 0 || timeout_ms == 0) return n;
    if (armed_ == kNever) {
      ADD_FAILURE() << "the backend would wait forever";
      errno = EINVAL;
      return -1;
    }
    clock = std::max(clock, armed_);
    armed_ = kNever;
    itimerspec spec{};
    spec.it_value.tv_nsec = 1;  // long past: expires at once
    (void)::timerfd_settime(timer_fd_, TFD_TIMER_ABSTIME, &spec, nullptr);
    return ::epoll_wait(epoll_fd, events, max_events, 0);
  }

  // Everything the backend has written to the socket, in order.
  std::vector<std::uint32_t> sent_ids() {
    std::vector<std::uint32_t> ids;
    can_frame f{};
    while (::recv(peer.get(), &f, sizeof f, MSG_DONTWAIT) == static_cast<ssize_t>(sizeof f)) {
      ids.push_back(f.can_id);
    }
    return ids;
  }
  // A frame for the backend to read.
  void inject(std::uint32_t can_id, std::array<std::uint8_t, 8> data = {}) {
    can_frame f{};
    f.can_id = can_id;
    f.len = 8;
    std::memcpy(f.data, data.data(), 8);
    ASSERT_EQ(::send(peer.get(), &f, sizeof f, MSG_DONTWAIT), static_cast<ssize_t>(sizeof f));
  }

 private:
  static int next(std::deque<int>& script) {
    if (script.empty()) return 0;
    const int e = script.front();
    script.pop_front();
    return e;
  }
  int timer_fd_ = -1;
  TimePoint armed_ = kNever;
};

struct Collect final : port::FrameReceiver {
  void on_frame(const can::CanFrame& frame, TimePoint) override { ids.push_back(frame.id); }
  std::vector<std::uint32_t> ids;
};

can::CanFrame frame(std::uint32_t id) {
  can::CanFrame f;
  f.id = id;
  f.len = 2;
  f.data[0] = static_cast<std::uint8_t>(id);
  return f;
}

std::vector<std::uint32_t> iota_ids(std::uint32_t first, std::uint32_t count) {
  std::vector<std::uint32_t> v;
  for (std::uint32_t i = 0; i < count; ++i) v.push_back(first + i);
  return v;
}

class BackendFault : public ::testing::Test {
 protected:
  SocketCanOptions options(BusOffRecovery policy = BusOffRecovery::kInterface) {
    SocketCanOptions o;
    o.interface = "can0";
    o.bus_off = policy;
    return o;
  }
  void send(SocketCanBackend& b, std::uint32_t id) { b.sink().send(frame(id), io.clock); }
  // One look at what is ready, without waiting (a deadline already due).
  void poll(SocketCanBackend& b) { b.wait(io.clock, rx); }
  // A wait that blocks until `deadline` on the test's clock.
  void wait_until(SocketCanBackend& b, TimePoint deadline) {
    for (int i = 0; io.clock < deadline; ++i) {
      ASSERT_LT(i, 100) << "time does not advance";
      b.wait(deadline, rx);
    }
  }

  FakeIo io;
  Collect rx;
};

// --- (1) EAGAIN: the socket's send buffer is full ------------------------------

TEST_F(BackendFault, FramesQueuedOnEagainGoOutInOrderWhenWritable) {
  SocketCanBackend b(options(), Logger(), io);
  ASSERT_TRUE(b.is_up());
  constexpr std::uint32_t kFrames = 40;
  for (std::uint32_t id = 0; id < kFrames; ++id) send(b, id);
  // The socketpair took a few, then said EAGAIN once; the rest wait in order
  // without another write() (no frame overtakes the queue).
  const std::size_t taken = b.stats().transmitted;
  ASSERT_GT(taken, 0u);
  ASSERT_EQ(b.transmit_queued(), kFrames - taken);
  EXPECT_EQ(io.eagains, 1);
  EXPECT_EQ(io.write_calls.size(), taken + 1);

  // Not writable: a wait of 50 ms makes no write() at all and does not
  // spin: one epoll_wait until the deadline's timer, one that finds it due.
  const auto writes = io.write_calls.size();
  const int waits = io.waits;
  b.wait(io.clock + milliseconds(50), rx);
  EXPECT_EQ(io.clock, kStart + milliseconds(50));
  EXPECT_EQ(io.write_calls.size(), writes);
  EXPECT_EQ(io.waits - waits, 2);

  // The far end drains; each time the socket is writable the queue moves.
  std::vector<std::uint32_t> out;
  int rounds = 0;
  while (b.transmit_queued() > 0 && rounds++ < 40) {
    auto got = io.sent_ids();
    out.insert(out.end(), got.begin(), got.end());
    const int before = io.waits;
    b.wait(io.clock + milliseconds(50), rx);
    EXPECT_LE(io.waits - before, 3) << "round " << rounds;
  }
  auto got = io.sent_ids();
  out.insert(out.end(), got.begin(), got.end());
  // Original order, none lost, none twice.
  EXPECT_EQ(out, iota_ids(0, kFrames));
  EXPECT_EQ(b.transmit_queued(), 0u);
  EXPECT_EQ(b.stats().transmitted, kFrames);
  EXPECT_EQ(b.stats().transmit_dropped, 0u);
  // Every write() either sent a frame or met EAGAIN, once per writable round.
  EXPECT_EQ(io.write_calls.size(), kFrames + static_cast<std::size_t>(io.eagains));
  EXPECT_LE(io.eagains, rounds + 1);
}

// --- (2) ENOBUFS: the interface's queue is full ---------------------------------

TEST_F(BackendFault, EnobufsIsRetriedOnABackedOffTimerInOrder) {
  SocketCanBackend b(options(), Logger(), io);
  // Seven refusals, then the interface takes frames again.
  io.write_errors = {ENOBUFS, ENOBUFS, ENOBUFS, ENOBUFS, ENOBUFS, ENOBUFS, ENOBUFS};
  send(b, 0x10);
  EXPECT_EQ(b.transmit_retry_at(), kStart + milliseconds(1));
  send(b, 0x11);
  send(b, 0x12);
  EXPECT_EQ(b.transmit_queued(), 3u);
  EXPECT_EQ(io.write_calls.size(), 1u) << "frames behind the first are not tried";

  wait_until(b, kStart + milliseconds(200));
  // Retries 1, 2, 4, 8, 16, 32 and 32 (the cap) ms apart; the eighth write
  // succeeds and the two frames behind follow at once.
  const auto at = [](int ms) { return kStart + milliseconds(ms); };
  EXPECT_EQ(io.write_calls, (std::vector<TimePoint>{at(0), at(1), at(3), at(7), at(15), at(31),
                                                    at(63), at(95), at(95), at(95)}));
  EXPECT_EQ(io.sent_ids(), (std::vector<std::uint32_t>{0x10, 0x11, 0x12}));
  EXPECT_EQ(b.transmit_queued(), 0u);
  EXPECT_EQ(b.transmit_retry_at(), kNever);
  EXPECT_EQ(b.stats().transmitted, 3u);
  EXPECT_EQ(b.stats().transmit_dropped, 0u);

  // A success resets the back-off: the next refusal waits 1 ms again.
  io.write_errors = {ENOBUFS};
  send(b, 0x13);
  EXPECT_EQ(b.transmit_retry_at(), io.clock + milliseconds(1));
}

// --- (3) error frames and bus-off ---------------------------------------------

// A controller error frame (linux/can/error.h): class CAN_ERR_CRTL, the
// status in data[1], the transmit and receive error counters in data[6]/[7].
std::array<std::uint8_t, 8> crtl(std::uint8_t status, std::uint8_t tx, std::uint8_t rx) {
  return {0, status, 0, 0, 0, 0, tx, rx};
}

TEST_F(BackendFault, ErrorFramesDriveTheBusStateAndCounters) {
  SocketCanBackend b(options(BusOffRecovery::kReport), Logger(), io);
  EXPECT_EQ(b.counters().state, BusState::kUnknown);  // no controller to ask

  io.inject(CAN_ERR_FLAG | CAN_ERR_CRTL, crtl(CAN_ERR_CRTL_TX_WARNING, 96, 5));
  poll(b);
  EXPECT_EQ(b.counters().state, BusState::kErrorWarning);
  EXPECT_EQ(b.counters().tx_errors, 96);
  EXPECT_EQ(b.counters().rx_errors, 5);

  io.inject(CAN_ERR_FLAG | CAN_ERR_CRTL, crtl(CAN_ERR_CRTL_RX_PASSIVE, 100, 128));
  poll(b);
  EXPECT_EQ(b.counters().state, BusState::kErrorPassive);
  EXPECT_EQ(b.counters().tx_errors, 100);
  EXPECT_EQ(b.counters().rx_errors, 128);

  // Bus-off, policy "report": it stays off, nobody restarts it, nothing is
  // written meanwhile.
  io.inject(CAN_ERR_FLAG | CAN_ERR_BUSOFF);
  poll(b);
  EXPECT_EQ(b.counters().state, BusState::kBusOff);
  EXPECT_NE(b.problem().find("bus-off"), std::string::npos) << b.problem();
  EXPECT_EQ(b.restart_at(), kNever);
  const auto writes = io.write_calls.size();
  send(b, 0x20);
  EXPECT_EQ(b.stats().transmit_dropped, 1u);
  EXPECT_EQ(io.write_calls.size(), writes);
  b.wait(io.clock + seconds(10), rx);
  EXPECT_EQ(b.counters().state, BusState::kBusOff);
  EXPECT_TRUE(io.restarts.empty());

  // Restarted from outside: error-active again, counters as the frame says.
  io.inject(CAN_ERR_FLAG | CAN_ERR_RESTARTED);
  poll(b);
  EXPECT_EQ(b.counters().state, BusState::kErrorActive);
  EXPECT_EQ(b.problem(), "");
  io.inject(CAN_ERR_FLAG | CAN_ERR_CRTL, crtl(CAN_ERR_CRTL_ACTIVE, 0, 0));
  poll(b);
  EXPECT_EQ(b.counters().state, BusState::kErrorActive);
  EXPECT_EQ(b.counters().tx_errors, 0);
  EXPECT_EQ(b.counters().rx_errors, 0);
  EXPECT_EQ(b.stats().error_frames, 5u);
  send(b, 0x21);
  EXPECT_EQ(io.sent_ids(), std::vector<std::uint32_t>{0x21});
}

// SIGUSR1's candump log: what is sent, what is received, and error frames
// with their identifier's flags, as candump -l writes them.
TEST_F(BackendFault, TheCandumpLogHasBothDirectionsAndErrorFrames) {
  SocketCanBackend b(options(BusOffRecovery::kReport), Logger(), io);
  const std::string path = ::testing::TempDir() + "backend-candump.log";
  std::remove(path.c_str());
  ASSERT_TRUE(b.candump().start(path, "can0").ok());
  send(b, 0x40D);
  io.inject(0x3C1, {0x1F, 0x02});  // 8 bytes, as inject sends them
  poll(b);
  io.inject(CAN_ERR_FLAG | CAN_ERR_CRTL, crtl(CAN_ERR_CRTL_TX_WARNING, 96, 5));
  poll(b);
  b.candump().stop();
  send(b, 0x40D);  // after the log stopped: not in it

  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 3u);
  const std::regex time(R"(^\(\d+\.\d{6}\) )");
  for (const auto& l : lines) EXPECT_TRUE(std::regex_search(l, time)) << l;
  EXPECT_NE(lines[0].find(") can0 40D#"), std::string::npos) << lines[0];
  EXPECT_NE(lines[1].find(") can0 3C1#1F02000000000000"), std::string::npos) << lines[1];
  EXPECT_NE(lines[2].find(") can0 20000004#0008000000006005"), std::string::npos) << lines[2];
  std::remove(path.c_str());
}

TEST_F(BackendFault, BusOffWithRestartPolicyCallsTheRestartAfterTheDelay) {
  SocketCanOptions o = options(BusOffRecovery::kRestart);
  o.restart_delay = milliseconds(200);
  SocketCanBackend b(o, Logger(), io);
  // A frame waiting behind ENOBUFS is dropped by bus-off, not kept.
  io.write_errors = {ENOBUFS};
  send(b, 0x30);
  ASSERT_EQ(b.transmit_queued(), 1u);

  io.inject(CAN_ERR_FLAG | CAN_ERR_BUSOFF);
  poll(b);
  EXPECT_EQ(b.counters().state, BusState::kBusOff);
  EXPECT_EQ(b.transmit_queued(), 0u);
  EXPECT_EQ(b.stats().transmit_dropped, 1u);
  EXPECT_EQ(b.restart_at(), kStart + milliseconds(200));

  // The first restart is refused (no CAP_NET_ADMIN): tried again a second
  // later, as the policy says the bridge restarts it.
  io.restart_errno = EPERM;
  wait_until(b, kStart + milliseconds(199));
  EXPECT_TRUE(io.restarts.empty());
  wait_until(b, kStart + milliseconds(1199));
  EXPECT_EQ(io.restarts, std::vector<TimePoint>{kStart + milliseconds(200)});
  EXPECT_EQ(b.restart_at(), kStart + milliseconds(1200));
  io.restart_errno = 0;
  wait_until(b, kStart + milliseconds(1500));
  EXPECT_EQ(io.restarts,
            (std::vector<TimePoint>{kStart + milliseconds(200), kStart + milliseconds(1200)}));
  EXPECT_EQ(b.stats().restarts, 2u);

  // The controller says it restarted: error-active, nothing more scheduled.
  io.inject(CAN_ERR_FLAG | CAN_ERR_RESTARTED);
  poll(b);
  EXPECT_EQ(b.counters().state, BusState::kErrorActive);
  EXPECT_EQ(b.restart_at(), kNever);
  EXPECT_EQ(b.problem(), "");
  wait_until(b, io.clock + seconds(5));
  EXPECT_EQ(io.restarts.size(), 2u);
}

TEST_F(BackendFault, AControllerFoundBusOffAtOpenIsRestartedByPolicy) {
  io.controller = true;
  io.controller_state = CAN_STATE_BUS_OFF;
  SocketCanBackend b(options(BusOffRecovery::kRestart), Logger(), io);
  EXPECT_EQ(b.counters().state, BusState::kBusOff);
  wait_until(b, kStart + seconds(1));
  EXPECT_EQ(io.restarts, std::vector<TimePoint>{kStart + milliseconds(500)});
}

// A bus-off and its recovery read in one wait: the state is the last one,
// and the loss is counted, so that the port's loop, which looks at the state
// only between waits, still learns of it.
TEST_F(BackendFault, ABusOffAndItsRecoveryInOneWaitAreCountedAsALoss) {
  SocketCanBackend b(options(BusOffRecovery::kInterface), Logger(), io);
  EXPECT_EQ(b.counters().losses, 0u);
  io.inject(CAN_ERR_FLAG | CAN_ERR_CRTL, crtl(CAN_ERR_CRTL_TX_PASSIVE, 128, 0));
  poll(b);
  EXPECT_EQ(b.counters().state, BusState::kErrorPassive);
  EXPECT_EQ(b.counters().losses, 0u) << "error-passive still carries frames";

  io.inject(CAN_ERR_FLAG | CAN_ERR_BUSOFF);
  io.inject(CAN_ERR_FLAG | CAN_ERR_RESTARTED);
  poll(b);
  EXPECT_EQ(b.counters().state, BusState::kErrorActive);
  EXPECT_EQ(b.counters().losses, 1u);

  // Another bus-off is another loss; a second report of it while the bus is
  // off is not.
  io.inject(CAN_ERR_FLAG | CAN_ERR_BUSOFF);
  io.inject(CAN_ERR_FLAG | CAN_ERR_BUSOFF);
  poll(b);
  EXPECT_EQ(b.counters().state, BusState::kBusOff);
  EXPECT_EQ(b.counters().losses, 2u);
}

// --- (4) the interface goes down or away ---------------------------------------

TEST_F(BackendFault, EnetdownOnWriteReportsTheBusDownAndReopensOnItsTimer) {
  SocketCanBackend b(options(), Logger(), io);
  ASSERT_EQ(io.opens.size(), 1u);
  io.write_errors = {ENOBUFS, ENETDOWN};
  send(b, 0x40);
  send(b, 0x41);
  io.link = LinkState::kDown;
  wait_until(b, kStart + milliseconds(1));  // the retry meets ENETDOWN
  EXPECT_FALSE(b.is_up());
  EXPECT_EQ(b.counters().state, BusState::kDown);
  EXPECT_EQ(b.counters().losses, 1u);
  EXPECT_EQ(b.problem(), "interface can0: " + errno_code(ENETDOWN).message());
  EXPECT_EQ(b.transmit_queued(), 0u);
  EXPECT_EQ(b.stats().transmit_dropped, 2u);
  EXPECT_EQ(b.reopen_at(), kStart + milliseconds(501));

  // While down: frames are dropped, the link is checked every 500 ms.
  const auto writes = io.write_calls.size();
  send(b, 0x42);
  EXPECT_EQ(io.write_calls.size(), writes);
  EXPECT_EQ(b.stats().transmit_dropped, 3u);
  const auto checks = io.link_checks.size();
  wait_until(b, kStart + milliseconds(1200));
  EXPECT_EQ(std::vector<TimePoint>(io.link_checks.begin() + static_cast<long>(checks),
                                   io.link_checks.end()),
            (std::vector<TimePoint>{kStart + milliseconds(501), kStart + milliseconds(1001)}));
  EXPECT_EQ(b.problem(), "interface can0 down");
  EXPECT_EQ(io.opens.size(), 1u);

  // Up again: a new socket at the next check, traffic resumes.
  io.link = LinkState::kUp;
  wait_until(b, kStart + milliseconds(1600));
  EXPECT_EQ(io.opens, (std::vector<TimePoint>{kStart, kStart + milliseconds(1501)}));
  EXPECT_TRUE(b.is_up());
  EXPECT_EQ(b.counters().state, BusState::kUnknown);
  EXPECT_EQ(b.problem(), "");
  EXPECT_EQ(b.reopen_at(), kNever);
  EXPECT_EQ(b.stats().reopens, 2u);
  send(b, 0x43);
  EXPECT_EQ(io.sent_ids(), std::vector<std::uint32_t>{0x43});
}

TEST_F(BackendFault, EnodevOnReadReportsTheBusDownAndReopensOnItsTimer) {
  SocketCanBackend b(options(), Logger(), io);
  io.read_errors = {0, ENODEV};
  io.inject(0x3C3);  // a poll response (Group 1 message 15) from MAC 3: delivered
  io.inject(0x3C3);  // this read meets ENODEV
  poll(b);
  EXPECT_EQ(rx.ids, std::vector<std::uint32_t>{0x3C3});
  EXPECT_FALSE(b.is_up());
  EXPECT_EQ(b.counters().state, BusState::kDown);
  EXPECT_EQ(b.problem(), "interface can0: " + errno_code(ENODEV).message());
  EXPECT_EQ(b.reopen_at(), kStart + milliseconds(500));
  EXPECT_EQ(io.opens.size(), 1u);

  wait_until(b, kStart + milliseconds(499));
  EXPECT_EQ(io.opens.size(), 1u);
  wait_until(b, kStart + milliseconds(700));
  EXPECT_EQ(io.opens, (std::vector<TimePoint>{kStart, kStart + milliseconds(500)}));
  EXPECT_TRUE(b.is_up());
  io.inject(0x3C3);
  poll(b);
  EXPECT_EQ(rx.ids, (std::vector<std::uint32_t>{0x3C3, 0x3C3}));
}

// --- (5) nothing to open at start ----------------------------------------------

// A rack service must start with an interface missing: the port reports it
// and opens the interface when it appears, on the same timer as above.
TEST_F(BackendFault, AnInterfaceAbsentAtStartIsReportedDownAndOpenedWhenItAppears) {
  io.link = LinkState::kAbsent;
  SocketCanBackend b(options(), Logger(), io);
  EXPECT_FALSE(b.is_up());
  EXPECT_EQ(b.counters().state, BusState::kDown);
  EXPECT_EQ(b.problem(), "interface can0 absent");
  EXPECT_EQ(b.reopen_at(), kStart + milliseconds(500));
  send(b, 0x40);  // dropped: nowhere to go
  EXPECT_EQ(b.stats().transmit_dropped, 1u);

  wait_until(b, kStart + milliseconds(1200));
  // Twice at start (is it CAN at all; can it be opened), then every 500 ms.
  EXPECT_EQ(io.link_checks, (std::vector<TimePoint>{kStart, kStart, kStart + milliseconds(500),
                                                    kStart + milliseconds(1000)}));
  EXPECT_TRUE(io.opens.empty());

  io.link = LinkState::kUp;
  wait_until(b, kStart + milliseconds(1600));
  EXPECT_EQ(io.opens, std::vector<TimePoint>{kStart + milliseconds(1500)});
  EXPECT_TRUE(b.is_up());
  EXPECT_EQ(b.problem(), "");
  send(b, 0x41);
  EXPECT_EQ(io.sent_ids(), std::vector<std::uint32_t>{0x41});
}

// No AF_CAN at all (this machine's kernel, for one): not a start-up failure
// either. The port says so, and keeps checking: the module may come later.
TEST_F(BackendFault, AKernelWithoutSocketCanIsReportedDownAndCheckedAgain) {
  io.kernel_can_errno = EAFNOSUPPORT;
  io.link = LinkState::kAbsent;
  SocketCanBackend b(options(), Logger(), io);
  EXPECT_FALSE(b.is_up());
  EXPECT_EQ(b.counters().state, BusState::kDown);
  EXPECT_EQ(b.problem(), "interface can0: this kernel has no SocketCAN (socket(AF_CAN): " +
                             errno_code(EAFNOSUPPORT).message() + ")");
  wait_until(b, kStart + milliseconds(1200));
  EXPECT_EQ(io.link_checks.size(), 4u);
  EXPECT_TRUE(io.opens.empty());

  // The module loaded and the interface created and set up.
  io.kernel_can_errno = 0;
  io.link = LinkState::kUp;
  wait_until(b, kStart + milliseconds(1600));
  EXPECT_EQ(io.opens, std::vector<TimePoint>{kStart + milliseconds(1500)});
  EXPECT_TRUE(b.is_up());
  EXPECT_EQ(b.counters().state, BusState::kUnknown);
}

// An interface that is there but not CAN is a configuration mistake: refused.
TEST_F(BackendFault, AnInterfaceThatIsNotCanIsRefusedAtStart) {
  io.link = LinkState::kNotCan;
  EXPECT_THROW(SocketCanBackend(options(), Logger(), io), std::runtime_error);
}

}  // namespace
}  // namespace dnbridge::socketcan
