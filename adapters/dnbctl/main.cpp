// dnbctl: the command-line client of dnbridge bridges, for people at a
// terminal and for scripts.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "adapters/dds/entity.hpp"
#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/usage_hint.hpp"
#include "adapters/security/check.hpp"
#include "adapters/security/toml_settings.hpp"
#include "adapters/version/version.hpp"

namespace {

using namespace dnbridge::dnbctl;

constexpr const char* kFooter =
    "Exit codes: 0 success; 1 the operation failed (refused, not applied, device error status); "
    "2 usage error (or a --security file missing or wrong); 3 nothing found (no bridge or node "
    "answered within the timeout).\n"
    "Every command has --help. Global options may come before or after the command.";

int code(Exit e) { return static_cast<int>(e); }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "dnbctl: inspect and command the pumps of dnbridge bridges (DeviceNet racks) over DDS."};
  app.footer(kFooter);
  app.set_version_flag("--version",
                       dnbridge::version::text("dnbctl", dnbridge::version::Dds::kUsed),
                       "Print the version, source revision and Cyclone DDS version, and exit");
  app.require_subcommand(1);
  app.fallthrough();  // global options are accepted after the command too

  GlobalOptions options;
  app.add_option("--domain", options.domain, "DDS domain (default 0, or $DNBCTL_DOMAIN)")
      ->envname("DNBCTL_DOMAIN")
      ->check(CLI::Range(0, 232));
  app.add_option("--rack", options.rack,
                 "Only this rack (needed when a MAC is on more than one rack)");
  app.add_option("--port", options.port, "Only this port of the rack(s)");
  app.add_option("--timeout", options.timeout_seconds,
                 "Seconds to wait for bridges to answer, and for each wait (default 3)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--json", options.json, "Machine-readable output: one JSON document");
  std::string security_file;
  app.add_option("--security", security_file,
                 "Join with DDS Security, with the [security] table of FILE (identity_ca, "
                 "certificate, private_key, permissions_ca, governance, permissions; relative "
                 "paths are relative to FILE). Default "
                 "$DNBCTL_SECURITY; without either, CYCLONEDDS_URI's configuration decides. "
                 "dnbctl refuses to start if a file is missing or wrong")
      ->envname("DNBCTL_SECURITY")
      ->type_name("FILE");

  ListArgs list;
  ShowArgs show;
  WatchArgs watch;
  OutputArgs pump;
  OutputArgs ballast;
  OutputArgs aout;
  DeviceOutputArgs outputs;
  ExplicitArgs get;
  ExplicitArgs set;
  ExplicitArgs service;
  EdsArgs eds;
  AssemblyArgs assembly;
  ParamArgs param;
  auto* list_cmd = add_list(app, list);
  auto* racks_cmd = add_racks(app);
  auto* watch_cmd = add_watch(app, watch);
  auto* pump_cmd = add_output(app, Output::kPump, pump);
  auto* ballast_cmd = add_output(app, Output::kBallast, ballast);
  auto* aout_cmd = add_output(app, Output::kAnalog, aout);
  auto* outputs_cmd = add_device_outputs(app, outputs);
  auto* get_cmd = add_explicit(app, ExplicitKind::kGet, get);
  auto* set_cmd = add_explicit(app, ExplicitKind::kSet, set);
  auto* service_cmd = add_explicit(app, ExplicitKind::kService, service);
  auto* show_cmd = add_show(app, show);
  auto* assembly_cmd = add_assembly(app, assembly);
  auto* scan_cmd = add_scan(app);
  auto* reload_cmd = add_reload(app);
  auto* eds_cmd = add_eds(app, eds);
  auto* param_cmd = add_param(app, param);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) {
      // A mistyped command or option: said with the closest known one.
      const std::string hint = usage_hint(
          app, std::span<const char* const>(argv + 1, static_cast<std::size_t>(argc - 1)));
      if (!hint.empty()) {
        std::fprintf(stderr, "dnbctl: %s\n", hint.c_str());
        return code(Exit::kUsage);
      }
    }
    const int rc = app.exit(e);  // prints help, or the error with a hint
    return rc == 0 ? 0 : code(Exit::kUsage);
  }

  if (!security_file.empty()) {
    try {
      options.security = dnbridge::security::load_file(security_file);
      (void)dnbridge::security::check(*options.security);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "dnbctl: %s\n", e.what());
      return code(Exit::kUsage);
    }
  }

  try {
    Exit rc = Exit::kOk;
    if (list_cmd->parsed()) rc = run_list(options, list);
    if (racks_cmd->parsed()) rc = run_racks(options);
    if (show_cmd->parsed()) rc = run_show(options, show);
    if (assembly_cmd->parsed()) rc = run_assembly(options, assembly);
    if (watch_cmd->parsed()) rc = run_watch(options, watch);
    if (pump_cmd->parsed()) rc = run_output(options, pump);
    if (ballast_cmd->parsed()) rc = run_output(options, ballast);
    if (aout_cmd->parsed()) rc = run_output(options, aout);
    if (outputs_cmd->parsed()) rc = run_device_outputs(options, outputs);
    if (get_cmd->parsed()) rc = run_explicit(options, get);
    if (set_cmd->parsed()) rc = run_explicit(options, set);
    if (service_cmd->parsed()) rc = run_explicit(options, service);
    if (scan_cmd->parsed()) rc = run_scan(options);
    if (reload_cmd->parsed()) rc = run_reload(options);
    if (eds_cmd->parsed()) rc = run_eds(options, eds);
    if (param_cmd->parsed()) rc = run_param(options, param);
    return code(rc);
  } catch (const CommandError& e) {
    std::fprintf(stderr, "dnbctl: %s\n", e.what());
    return code(e.code());
  } catch (const dnbridge::dds::Error& e) {
    std::fprintf(stderr, "dnbctl: DDS: %s\n", e.what());
    return code(Exit::kFailed);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dnbctl: %s\n", e.what());
    return code(Exit::kFailed);
  }
}
