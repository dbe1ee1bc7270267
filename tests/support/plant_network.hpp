#pragma once
// A plant network made of network namespaces, for tests that run programs on
// several hosts: a switch (a Linux bridge in a namespace of its own) and one
// namespace per host, cabled to it by a veth pair. Nothing of this machine's
// own network is touched. Needs root; the ip program is DNBRIDGE_IP.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "e2e/child_process.hpp"

namespace dnbridge::plant {

// Runs `command` through the shell; false (and says so) when it fails.
inline bool sh(std::string command) {
  if (command.rfind("ip ", 0) == 0) command.replace(0, 2, DNBRIDGE_IP);
  const int rc = std::system((command + " 2>&1").c_str());
  if (rc != 0) ADD_FAILURE() << "failed (" << rc << "): " << command;
  return rc == 0;
}

// The plant network: a switch (a Linux bridge in namespace PREFIX-plant)
// and one host namespace per name, PREFIX-NAME, with eth0 cabled to the
// switch's port NAME at 10.99.0.N/24. Removed at destruction. PREFIX is
// "dnbmh" and the test process's pid, whichever test suite makes it: that is
// how remove_stale() knows the namespaces of a test process that is gone.
class PlantNetwork {
 public:
  explicit PlantNetwork(std::vector<std::string> hosts)
      : prefix_("dnbmh" + std::to_string(getpid())), hosts_(std::move(hosts)) {
    remove_stale();
    const std::string plant = prefix_ + "-plant";
    ok_ = sh("ip netns add " + plant) && sh("ip -n " + plant + " link set lo up") &&
          sh("ip -n " + plant + " link add switch type bridge") &&
          sh("ip -n " + plant + " link set switch up");
    for (std::size_t i = 0; ok_ && i < hosts_.size(); ++i) {
      const std::string ns = name_space(hosts_[i]);
      ok_ = sh("ip netns add " + ns) && sh("ip -n " + ns + " link set lo up") &&
            sh("ip -n " + plant + " link add " + hosts_[i] + " type veth peer name eth0 netns " +
               ns) &&
            sh("ip -n " + plant + " link set " + hosts_[i] + " master switch up") &&
            sh("ip -n " + ns + " addr add 10.99.0." + std::to_string(i + 1) + "/24 dev eth0") &&
            sh("ip -n " + ns + " link set eth0 up");
    }
  }
  ~PlantNetwork() {
    for (const auto& h : hosts_)
      std::system((DNBRIDGE_IP " netns del " + name_space(h) + " 2>/dev/null").c_str());
    std::system((DNBRIDGE_IP " netns del " + prefix_ + "-plant 2>/dev/null").c_str());
  }
  PlantNetwork(const PlantNetwork&) = delete;
  PlantNetwork& operator=(const PlantNetwork&) = delete;

  // Namespaces a killed test process left behind (its pid is gone, or is
  // this process's now), with the processes it had started in them (its
  // bridges and hosts, which outlive it): killed first, as a namespace that
  // still holds a process lives on after its name is deleted.
  static void remove_stale() {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator("/run/netns", ec)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("dnbmh", 0) != 0) continue;
      const auto pid = static_cast<pid_t>(std::atol(name.c_str() + 5));
      // Also this process's: left by an earlier process with the same pid.
      if (pid > 0 && (pid == getpid() || (::kill(pid, 0) != 0 && errno == ESRCH))) {
        std::system(
            (DNBRIDGE_IP " netns pids " + name + " 2>/dev/null | xargs -r kill -KILL").c_str());
        std::system((DNBRIDGE_IP " netns del " + name + " 2>/dev/null").c_str());
      }
    }
  }

  bool ok() const { return ok_; }
  std::string name_space(const std::string& host) const { return prefix_ + "-" + host; }

  // `host`'s cable, at the switch.
  bool cut(const std::string& host) {
    return sh("ip -n " + prefix_ + "-plant link set " + host + " down");
  }
  bool mend(const std::string& host) {
    return sh("ip -n " + prefix_ + "-plant link set " + host + " up");
  }

  // `args` run on `host`.
  std::vector<std::string> on(const std::string& host, std::vector<std::string> args) const {
    args.insert(args.begin(), {DNBRIDGE_IP, "netns", "exec", name_space(host)});
    return args;
  }

 private:
  std::string prefix_;
  std::vector<std::string> hosts_;
  bool ok_ = false;
};

// A DDS program on a plant host, with Cyclone as deploy/ ships it for a
// plant network (deploy/cyclonedds/cyclonedds.xml: multicast discovery);
// `control`: its stdin and stdout the test's (ChildOptions::control), else
// its stderr captured.
inline e2e::ChildOptions deployed_cyclone(bool control) {
  e2e::ChildOptions o;
  o.env = {"CYCLONEDDS_URI=file://" DNBRIDGE_SOURCE_DIR "/deploy/cyclonedds/cyclonedds.xml"};
  o.control = control;
  o.capture_stderr = !control;
  return o;
}

// A program on a host of the plant, talked with a line at a time on its
// stdin and stdout (ChildOptions::control); every line it printed is kept.
class HostProgram {
 public:
  HostProgram(const PlantNetwork& net, const std::string& host, std::vector<std::string> args,
              const e2e::ChildOptions& options)
      : child_(net.on(host, std::move(args)), options) {}

  bool send(const std::string& line) { return child_.send_line(line); }

  // Its lines, read until one satisfies `wanted`; nullopt at the timeout.
  std::optional<std::string> until(const std::function<bool(const std::string&)>& wanted,
                                   std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() < 0) return std::nullopt;
      auto line = child_.read_line(left);
      if (!line) return std::nullopt;
      transcript_ += *line + "\n";
      if (wanted(*line)) return line;
    }
  }
  std::optional<std::string> until(const std::string& prefix,
                                   std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    return until([&](const std::string& l) { return l.rfind(prefix, 0) == 0; }, timeout);
  }

  // Until it has printed a line that starts with each of `lines`, among
  // all it printed so far or within `timeout`; false at the timeout.
  bool printed(const std::vector<std::string>& lines, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    const auto all_there = [&] {
      const std::string all = "\n" + transcript_;
      for (const auto& l : lines) {
        if (all.find("\n" + l) == std::string::npos) return false;
      }
      return true;
    };
    while (!all_there()) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() < 0 || !until([](const std::string&) { return true; }, left)) return false;
    }
    return true;
  }

  const std::string& transcript() const { return transcript_; }
  e2e::ChildProcess& child() { return child_; }

 private:
  e2e::ChildProcess child_;
  std::string transcript_;
};

}  // namespace dnbridge::plant
