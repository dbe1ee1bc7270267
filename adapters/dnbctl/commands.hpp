#pragma once
// dnbctl's commands, one group per file: each adds its subcommand(s) to the
// command line (add_*) and runs when chosen (run_*). A run returns the exit
// code or throws CommandError; output goes to stdout, errors to stderr.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "adapters/dnbctl/client.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/options.hpp"
#include "bridge/profiles/eds/eds_file.hpp"

namespace dnbridge::dnbctl {

// The client of this process: "dnbctl user@host:pid" on the options' domain.
Client make_client(const GlobalOptions& options);

// Prints `text` on stdout as it is.
void print(const std::string& text);

// --- inspect_commands.cpp: list, racks, show ------------------------------------
// What list, racks and scan share: whether a port the options allow was
// heard; waiting until one is (else CommandError kNotFound), a moment for
// other bridges, then until nothing is `missing` or the timeout (a note on
// stderr says what is missing); what is missing of the allowed ports' nodes.
bool any_port(const Client& client, const GlobalOptions& o);
void gather(Client& client, const GlobalOptions& o, const std::function<bool()>& found,
            const std::function<std::string()>& missing);
std::string nodes_missing(const Client& client, const GlobalOptions& o);
// The nodes the options allow, each with its PumpState when seen.
std::vector<NodeRow> node_rows(const Client& client, const GlobalOptions& o);

struct ListArgs {
  bool nodes_only = false;
  bool ports_only = false;
};
CLI::App* add_list(CLI::App& app, ListArgs& args);
Exit run_list(const GlobalOptions& options, const ListArgs& args);

// racks: takes only the global options.
CLI::App* add_racks(CLI::App& app);
Exit run_racks(const GlobalOptions& options);

struct ShowArgs {
  std::string node;  // MAC ID or name
};
CLI::App* add_show(CLI::App& app, ShowArgs& args);
Exit run_show(const GlobalOptions& options, const ShowArgs& args);

// --- watch_command.cpp ---------------------------------------------------------------
struct WatchArgs {
  std::vector<std::string> nodes;  // MAC IDs or names
  bool lines = false;
  std::uint64_t count = 0;      // 0: no limit
  double duration_seconds = 0;  // 0: no limit
};
CLI::App* add_watch(CLI::App& app, WatchArgs& args);
Exit run_watch(const GlobalOptions& options, const WatchArgs& args);

// --- output_commands.cpp: pump, ballast, aout, outputs ------------------------------
enum class Output { kPump, kBallast, kAnalog };
struct OutputArgs {
  Output output = Output::kPump;
  std::string node;    // MAC ID or name
  std::string value;   // on|off, or the analog value
  std::string issuer;  // default "dnbctl user@host"
  std::int32_t strength = 10;
  double hold_for_seconds = 0;
};
CLI::App* add_output(CLI::App& app, Output output, OutputArgs& args);
Exit run_output(const GlobalOptions& options, const OutputArgs& args);

// outputs: a device's outputs (DeviceCommand), by field or as bytes.
struct DeviceOutputArgs {
  std::string node;                 // MAC ID or name
  std::vector<std::string> fields;  // NAME=VALUE
  std::string bytes;                // hex, instead of the fields
  std::string issuer;
  std::int32_t strength = 10;
  double hold_for_seconds = 0;
};
CLI::App* add_device_outputs(CLI::App& app, DeviceOutputArgs& args);
Exit run_device_outputs(const GlobalOptions& options, const DeviceOutputArgs& args);

// --- explicit_commands.cpp: get, set, service --------------------------------------
enum class ExplicitKind { kGet, kSet, kService };
struct ExplicitArgs {
  ExplicitKind kind = ExplicitKind::kGet;
  std::string node;  // MAC ID or name
  std::string service;
  std::string class_id;
  std::string instance_id;
  std::string attribute;
  std::string data;
  std::string as;
};
CLI::App* add_explicit(CLI::App& app, ExplicitKind kind, ExplicitArgs& args);
Exit run_explicit(const GlobalOptions& options, const ExplicitArgs& args);

// --- assembly_command.cpp -----------------------------------------------------------------
struct AssemblyArgs {
  std::string node;      // MAC ID or name
  std::string instance;  // one instance, or empty: every one up to the max
};
CLI::App* add_assembly(CLI::App& app, AssemblyArgs& args);
Exit run_assembly(const GlobalOptions& options, const AssemblyArgs& args);

// --- scan_command.cpp ------------------------------------------------------------------
// scan: takes only the global options (--rack, --port, --json, --timeout).
CLI::App* add_scan(CLI::App& app);
Exit run_scan(const GlobalOptions& options);

// --- reload_command.cpp ----------------------------------------------------------------
// reload: takes only the global options (--rack, --json, --timeout; --port
// is refused: a reload is a rack's).
CLI::App* add_reload(CLI::App& app);
Exit run_reload(const GlobalOptions& options);

// --- eds_command.cpp: eds check ---------------------------------------------------------
// Needs no bridge: reads a file (--json for the result as one document).
struct EdsArgs {
  std::string file;
};
CLI::App* add_eds(CLI::App& app, EdsArgs& args);
Exit run_eds(const GlobalOptions& options, const EdsArgs& args);
// The EDS file at `path`, as the bridge reads it; CommandError (usage) with
// its errors when it is not usable.
profiles::eds::EdsFile read_eds(const std::string& path);

// --- param_command.cpp: param --------------------------------------------------------------
// A device's parameter (Parameter object, class 0x0F) read or written by its
// name in the device's EDS, through the bridge's explicit gateway.
struct ParamArgs {
  std::string node;   // MAC ID or name
  std::string param;  // the EDS's name, ParamN or N
  std::string value;  // empty: read
  std::string eds;    // the device's EDS file
};
CLI::App* add_param(CLI::App& app, ParamArgs& args);
Exit run_param(const GlobalOptions& options, const ParamArgs& args);

}  // namespace dnbridge::dnbctl
