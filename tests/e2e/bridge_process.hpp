#pragma once
// The bridge executable (dnbridge-sim) in a process of its own, on `dnbridge-sim --simulate`'s
// configuration (the embedded default rack) on this process's domain,
// logging warnings only. CYCLONEDDS_URI (loopback, this process's discovery
// tag) is inherited.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "dds/dds_fixture.hpp"
#include "support/simulated_rack.hpp"

namespace dnbridge::e2e {

// `dnbridge-sim --simulate`'s configuration, on `domain`, logging warnings only.
inline std::filesystem::path write_simulated_rack_config(dds_domainid_t domain) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("dnbridge-e2e-" + std::to_string(getpid()) + ".toml");
  std::ofstream(path) << support::simulated_rack_config(domain, "sim-rack", "warn");
  return path;
}

// `binary` (the dnbridge executable) running that configuration until
// destroyed (then killed, if it has not exited).
class BridgeProcess {
 public:
  explicit BridgeProcess(const std::string& binary = DNBRIDGE_BINARY,
                         const ChildOptions& options = {})
      : config_(write_simulated_rack_config(dds::testing::test_domain())) {
    child_.emplace(std::vector<std::string>{binary, "--config", config_.string()}, options);
  }
  ~BridgeProcess() {
    child_.reset();
    std::filesystem::remove(config_);
  }
  BridgeProcess(const BridgeProcess&) = delete;
  BridgeProcess& operator=(const BridgeProcess&) = delete;

  ChildProcess& child() { return *child_; }

  // Its resident set (VmRSS in /proc/PID/status), in KiB; 0 if unreadable.
  long rss_kib() const {
    std::ifstream status("/proc/" + std::to_string(child_->pid()) + "/status");
    std::string line;
    while (std::getline(status, line)) {
      if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
    }
    return 0;
  }

 private:
  std::filesystem::path config_;
  std::optional<ChildProcess> child_;
};

}  // namespace dnbridge::e2e
