// The bridge's Prometheus endpoint ([metrics] listen), scraped over HTTP as
// Prometheus would, and checked with Prometheus's own promtool.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "e2e/bridge_fixture.hpp"

namespace dnbridge::e2e {
namespace {

// GET /metrics from 127.0.0.1:`port`: the response body, or "" if none.
std::string scrape(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return {};
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string response;
  timeval timeout{5, 0};
  (void)::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0) {
    const std::string request = "GET /metrics HTTP/1.0\r\nHost: localhost\r\n\r\n";
    if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) ==
        static_cast<ssize_t>(request.size())) {
      char buffer[4096];
      for (ssize_t n; (n = ::recv(fd, buffer, sizeof buffer, 0)) > 0;) {
        response.append(buffer, static_cast<std::size_t>(n));
      }
    }
  }
  ::close(fd);
  const auto body = response.find("\r\n\r\n");
  return body == std::string::npos ? std::string{} : response.substr(body + 4);
}

// promtool check metrics on `text`: its exit status and what it printed.
std::pair<int, std::string> promtool(const std::string& text) {
  const std::string in = ::testing::TempDir() + "metrics.txt";
  const std::string out = ::testing::TempDir() + "promtool.txt";
  std::ofstream(in) << text;
  const int status =
      std::system(("\"" PROMTOOL "\" check metrics < '" + in + "' > '" + out + "' 2>&1").c_str());
  std::ifstream f(out);
  std::string said((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, said};
}

TEST_F(BridgeTest, MetricsAreServedAndPassPromtool) {
  auto config = rack_config();
  config.metrics_listen = "127.0.0.1:0";  // any free port
  ASSERT_NO_FATAL_FAILURE(start_online(std::move(config)));
  ASSERT_NE(bridge_->metrics_server(), nullptr);
  const auto ports = bridge_->metrics_server()->ports();
  ASSERT_FALSE(ports.empty());
  // The metrics take a node's status when NodeStatus is written: once the
  // supervisor has every node's online status, so do the metrics.
  ASSERT_TRUE(nodes_.until([&] {
    for (unsigned mac = 1; mac <= kPumps; ++mac) {
      const auto* n = nodes_.latest(pump_mac(mac));
      if (!n || n->state != dnbridge_NODE_ONLINE) return false;
    }
    return true;
  }));

  const std::string text = scrape(ports.front());
  ASSERT_FALSE(text.empty()) << "no response from port " << ports.front();
  for (unsigned mac = 1; mac <= kPumps; ++mac) {
    const std::string series = fmt::format(
        "dnbridge_node_online{{rack=\"sim-rack\",port=\"A\",mac=\"{}\",name=\"pump-{}\"}} 1\n", mac,
        mac);
    EXPECT_NE(text.find(series), std::string::npos) << series << "in:\n" << text;
  }
  for (const char* line :
       {"dnbridge_port_up{rack=\"sim-rack\",port=\"A\"} 1\n",
        "dnbridge_port_nodes_online{rack=\"sim-rack\",port=\"A\"} 8\n",
        "dnbridge_port_state{rack=\"sim-rack\",port=\"A\",state=\"running\"} 1\n",
        "dnbridge_can_bus_state{rack=\"sim-rack\",port=\"A\",state=\"error-active\"} 1\n",
        "# TYPE dnbridge_node_polls_total counter\n", "# TYPE dnbridge_can_frames_total counter\n",
        "# TYPE dnbridge_dds_queue_depth gauge\n",
        "dnbridge_dds_samples_taken_total{rack=\"sim-rack\",topic=\"PumpCommand\"} 0\n",
        "dnbridge_dds_command_holdoffs_total{rack=\"sim-rack\"} 0\n",
        "dnbridge_dds_state_write_failures_total{rack=\"sim-rack\"} 0\n"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << "in:\n" << text;
  }
  const auto [status, said] = promtool(text);
  EXPECT_EQ(status, 0) << said << "\non:\n" << text;
}

TEST_F(BridgeTest, AMetricsAddressInUseIsASetUpFailureThatSaysSo) {
  // A port of this host already taken.
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0);
  ASSERT_EQ(::listen(fd, 1), 0);
  socklen_t len = sizeof addr;
  ASSERT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len), 0);
  auto config = rack_config();
  config.metrics_listen = fmt::format("127.0.0.1:{}", ntohs(addr.sin_port));
  try {
    daemon::Daemon bridge(std::move(config), log_, daemon::simulated_backend_factory(log_));
    ADD_FAILURE() << "the bridge was made with its metrics port taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("[metrics] listen = \"127.0.0.1:"), std::string::npos)
        << e.what();
  }
  ::close(fd);
}

}  // namespace
}  // namespace dnbridge::e2e
