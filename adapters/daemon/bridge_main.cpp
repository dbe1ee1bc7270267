#include "adapters/daemon/bridge_main.hpp"

#include <fmt/format.h>
#include <signal.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/daemon.hpp"
#include "adapters/daemon/log_sink.hpp"
#include "adapters/daemon/service_notify.hpp"
#include "adapters/dds/loopback.hpp"
#include "adapters/security/check.hpp"
#include "adapters/version/version.hpp"

namespace dnbridge::daemon {
namespace {

// Exit codes: 0 stopped in order; 1 failed while running or at set-up;
// 2 bad command line or configuration.
constexpr int kFailed = 1;
constexpr int kBadConfiguration = 2;

std::optional<LogLevel> parse_level(const std::string& s) {
  for (auto level :
       {LogLevel::kTrace, LogLevel::kDebug, LogLevel::kInfo, LogLevel::kWarn, LogLevel::kError}) {
    if (s == to_string(level)) return level;
  }
  return std::nullopt;
}

// Who the bridge is on DDS, as --check-config and the log say it.
std::string security_text(const security::Identity& identity) {
  return fmt::format("DDS Security as {} (certificate valid until {})", identity.subject,
                     identity.valid_until);
}

// --check-config FILE: what the file configures, or why it cannot serve.
int check_config(const std::string& file) {
  try {
    auto c = load_config_file(file);
    for (const auto& w : c.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    std::string security;
    if (c.security) security = ", " + security_text(security::check(*c.security));
    std::size_t nodes = 0;
    for (const auto& p : c.ports) nodes += p.nodes.size();
    std::printf("%s: rack %s, %zu port(s), %zu node(s)%s: OK\n", file.c_str(), c.rack.c_str(),
                c.ports.size(), nodes, security.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kBadConfiguration;
  }
}

// SIGINT, SIGTERM, SIGUSR1 and SIGHUP are taken by sigwait(): blocked
// before any thread starts, so no other thread is interrupted by them.
sigset_t block_signals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGUSR1);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  return signals;
}

// Runs the bridge until SIGINT or SIGTERM; SIGHUP reads the configuration
// again, SIGUSR1 toggles the candump logs.
int run_until_stopped(const DaemonConfig& config, StderrLogSink& log, ReloadSource reload,
                      const Program& program, const sigset_t& signals,
                      const std::string& candump_dir) {
  Logger main_log(log, "dnbridge");
  try {
    Daemon bridge(config, log,
                  program.simulated_backends != nullptr ? program.simulated_backends(log)
                                                        : default_backend_factory(log),
                  std::move(reload));
    bridge.start();
    ServiceNotifier service(bridge, Logger(log, "systemd"));
    service.start();
    main_log.info(
        "running ({}); SIGINT or SIGTERM stops it in order, SIGHUP reads the configuration again, "
        "SIGUSR1 toggles candump logs",
        config.source);
    int signal = 0;
    for (;;) {
      sigwait(&signals, &signal);
      if (signal == SIGUSR1) {
        bridge.toggle_candump(candump_dir);
      } else if (signal == SIGHUP) {
        bridge.request_reload({});
      } else {
        break;
      }
    }
    main_log.info("{}: stopping", signal == SIGINT ? "SIGINT" : "SIGTERM");
    service.stopping();
    bridge.stop();
  } catch (const std::exception& e) {
    main_log.error("{}", e.what());
    return kFailed;
  }
  return 0;
}

}  // namespace

int bridge_main(int argc, char** argv, const Program& program) {
  const bool with_simulator = program.simulated_backends != nullptr;
  CLI::App app{fmt::format(
      "{}: the DeviceNet master of an equipment rack's CAN ports, publishing its pumps as\n"
      "typed DDS topics (dnbridge/PumpState, NodeStatus, PortStatus) and taking commands\n"
      "(dnbridge/PumpCommand) and explicit requests (dnbridge/ExplicitRequest).{}",
      program.name,
      with_simulator ? "\nWith the simulator: a port whose interface is \"simulated\" runs on an\n"
                       "in-process simulated bus of CDN127s."
                     : "")};
  std::string config_file;
  std::string check_file;
  bool simulate = false;
  bool print_default = false;
  std::string level_name;
  auto* config_opt =
      app.add_option("-c,--config", config_file, "The rack's configuration file (TOML)")
          ->check(CLI::ExistingFile);
  auto* simulate_opt = app.add_flag(
      "--simulate", simulate,
      with_simulator ? "Run the embedded default: a simulated rack of CDN127 pumps on the "
                       "in-process bus"
                     : "Not in this program: dnbridge-sim runs the simulated rack");
  app.add_option("--check-config", check_file, "Check a configuration file and exit");
  app.add_flag("--print-default-config", print_default,
               "Print the embedded default configuration and exit");
  app.add_option("--log-level", level_name,
                 "trace, debug, info, warn or error (default: the file's)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  std::string candump_dir = "/tmp";
  app.add_option("--candump-dir", candump_dir,
                 "Where SIGUSR1 starts (and the next SIGUSR1 stops) a candump -l compatible log "
                 "of each port's traffic, error frames included, dnbridge-PORT-candump.log")
      ->capture_default_str();
  config_opt->excludes(simulate_opt);
  app.set_version_flag("--version", version::text(program.name, version::Dds::kUsed),
                       "Print the version, source revision and Cyclone DDS version, and exit");
  CLI11_PARSE(app, argc, argv);

  if (print_default) {
    std::fputs(std::string(embedded_default_config_text()).c_str(), stdout);
    return 0;
  }
  if (!check_file.empty()) return check_config(check_file);
  if (simulate && !with_simulator) {
    std::fprintf(stderr,
                 "%s carries no simulator: dnbridge-sim runs the simulated rack (the same "
                 "program with the simulator linked in)\n",
                 std::string(program.name).c_str());
    return kBadConfiguration;
  }
  if (config_file.empty() && !simulate) {
    std::fprintf(stderr, "give --config FILE%s (--help)\n",
                 with_simulator ? ", or --simulate for the embedded default" : "");
    return kBadConfiguration;
  }

  DaemonConfig config;
  std::optional<security::Identity> identity;
  try {
    config = simulate ? embedded_default_config() : load_config_file(config_file);
    // Security asked for and a file wrong: no participant at all.
    if (config.security) identity = security::check(*config.security);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kBadConfiguration;
  }
  // The simulated rack stays on this host unless told otherwise.
  const bool pinned = simulate && std::getenv("CYCLONEDDS_URI") == nullptr;
  if (pinned) setenv("CYCLONEDDS_URI", dds::loopback_config().c_str(), 0);

  // A level given on the command line stays through reloads.
  if (!level_name.empty()) config.log_level = *parse_level(level_name);
  StderrLogSink log(config.log_level);
  log.add_field("RACK", config.rack);
  Logger main_log(log, "dnbridge");
  for (const auto& w : config.warnings)
    main_log.warn("{}", w);  // each warning starts with FILE:LINE:COLUMN
  if (identity) {
    main_log.info("{}", security_text(*identity));
  }
  if (pinned) {
    main_log.info(
        "DDS pinned to loopback (CYCLONEDDS_URI was not set; see "
        "deploy/cyclonedds/loopback.xml)");
  }

  const sigset_t signals = block_signals();

  ReloadSource reload;
  if (!config_file.empty()) {
    reload.load = [config_file, level_name] {
      DaemonConfig c = load_config_file(config_file);
      if (!level_name.empty()) c.log_level = *parse_level(level_name);
      return c;
    };
    reload.set_log_level = [&log](LogLevel level) { log.set_level(level); };
  }

  return run_until_stopped(config, log, std::move(reload), program, signals, candump_dir);
}

}  // namespace dnbridge::daemon
