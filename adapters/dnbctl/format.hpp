#pragma once
// How dnbctl shows what it read: readable tables and lines for people, and
// the same content as JSON for scripts. Pure functions of the IDL structs
// (idl/dnbridge.idl) and plain values: no DDS entity is touched here. Each
// record (a port, a node, a pump, an explicit exchange) is one Record
// (record.hpp), from which its table row, its lines and its JSON are made.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/dnbctl/json.hpp"
#include "adapters/dnbctl/record.hpp"
#include "adapters/dnbctl/values.hpp"
#include "dnbridge.h"

namespace dnbridge::dnbctl {

// --- Names --------------------------------------------------------------------
// The states' names (adapters/dds/states.hpp: the same as in the logs).
std::string_view to_text(dnbridge_NodeLifecycle state);  // "online", "wrong device", ...
std::string_view to_text(dnbridge_PortLifecycle state);  // "running", "duplicate MAC", ...
std::string_view to_text(dnbridge_BusState state);       // "error-active", "bus-off", ...
// An ExplicitReply status (STATUS_*): "transaction completed", ...
std::string transaction_status_text(std::uint8_t status);
// A CIP general status: "success", "attribute not supported", or "reserved (0x..)".
std::string general_status_text(std::uint8_t code);
// A CIP service: "Get_Attribute_Single", or "service 0x4E".
std::string service_text(std::uint8_t service);
// "sim-rack/A/3": how dnbctl names a node.
std::string node_name(std::string_view rack, std::string_view port, unsigned mac);

// --- Tables ---------------------------------------------------------------------
// Columns left-aligned and separated by two spaces, a header line first; no
// trailing blanks.
class Table {
 public:
  explicit Table(std::vector<std::string> headers) : headers_(std::move(headers)) {}
  void add(std::vector<std::string> row) { rows_.push_back(std::move(row)); }
  std::string render() const;

 private:
  std::vector<std::string> headers_;
  std::vector<std::vector<std::string>> rows_;
};

// Records as one column per label, the headers the labels in capitals, each
// cell the record's text_of(label).
std::string table(std::span<const std::string_view> labels, std::span<const Record> rows);

// --- list -------------------------------------------------------------------------
// `alive`: whether the bridge that wrote the sample is still there (a state
// instance whose writer left stays readable, NOT_ALIVE_NO_WRITERS).
struct PortRow {
  const dnbridge_PortStatus* port = nullptr;
  bool alive = true;
};
struct NodeRow {
  const dnbridge_NodeStatus* node = nullptr;
  const dnbridge_PumpState* pump = nullptr;  // none when not (yet) seen, or not a pump
  bool alive = true;
  const dnbridge_DeviceState* device = nullptr;  // a device of profile "eds", when seen

  // What the node's state topic (PumpState or DeviceState) says, when seen.
  std::optional<bool> online() const;
  std::optional<bool> outputs_idle() const;
  std::string_view idle_reason() const;
  std::string_view commanded_by() const;
};

// Whether a node is online as dnbctl shows it: its bridge is there, and it
// is polled (PumpState's or DeviceState's `online`, else the NodeStatus state).
bool node_online(const NodeRow& row);
// A port's PortStatus as every command shows it.
Record port_record(const dnbridge_PortStatus& p);
// The members of a port's JSON object (list, racks).
void port_json_members(JsonWriter& out, const dnbridge_PortStatus& p);

std::string ports_table(std::span<const PortRow> ports);
std::string nodes_table(std::span<const NodeRow> nodes);
// {"racks": [{"rack", "bridge_alive", "ports": [{..., "nodes": [...]}]}]}
// Nodes whose port has no PortStatus are listed under a port of their own
// with only its name.
void list_json(JsonWriter& out, std::span<const PortRow> ports, std::span<const NodeRow> nodes);

// --- watch --------------------------------------------------------------------------
// One line per sample: "12:00:01.250 sim-rack/A/3 pump-3 online running ... | pump on ...".
std::string pump_line(const dnbridge_PumpState& s, std::string_view time_text);
std::string pumps_table(std::span<const dnbridge_PumpState* const> pumps);
void pump_json(JsonWriter& out, const dnbridge_PumpState& s);
// The outputs as they read: "pump on, N2 ballast off, analog out 2048 (5.001 V)".
std::string outputs_text(bool pump_on, bool n2_ballast_on, std::uint16_t analog_raw);

// --- show -----------------------------------------------------------------------------
// `device`: a device's DeviceState (profile "eds"), when seen: its data too.
std::string node_details(const dnbridge_NodeStatus& n, const dnbridge_PumpState* pump, bool alive,
                         const dnbridge_DeviceState* device = nullptr);
void node_json(JsonWriter& out, const dnbridge_NodeStatus& n, const dnbridge_PumpState* pump,
               bool alive, const dnbridge_DeviceState* device = nullptr);

// --- get, set, service --------------------------------------------------------------
struct ExplicitExchange {
  // The request.
  std::string rack;
  std::string port;
  std::uint8_t mac = 0;
  std::uint8_t service = 0;
  std::uint16_t class_id = 0;
  std::uint16_t instance_id = 0;
  std::optional<std::uint8_t> attribute;
  std::vector<std::uint8_t> request_data;
  // The reply.
  std::uint8_t status = 0;
  std::uint8_t general_status = 0;
  std::uint8_t additional_status = 0xFF;
  std::vector<std::uint8_t> data;
  std::string message;

  // The bridge completed the transaction and the device answered success.
  bool succeeded() const noexcept { return status == 1 && general_status == 0; }
};

// Why an exchange that did not succeed failed: the bridge's status with its
// message (e.g. the [explicit_policy] key that would allow it), or the
// device's general status.
std::string failure_text(const ExplicitExchange& x);

// `decoded`: the data decoded as asked with --as (none without --as).
std::string explicit_text(const ExplicitExchange& x, Decoding as,
                          const std::optional<Parsed<std::string>>& decoded);
void explicit_json(JsonWriter& out, const ExplicitExchange& x, Decoding as,
                   const std::optional<Parsed<std::string>>& decoded);

// --- reload ---------------------------------------------------------------------------
// A ReloadReply's status (RELOAD_*) as one word: "applied", "refused",
// "busy", "no-file", "incomplete"; "unknown" for any other value.
std::string_view reload_status_word(std::uint8_t status);
// "rack R: " and the bridge's message, the file read, then the lines
// applied, those that need a restart and the problems, each list under its
// heading ("applied:", "needs a restart:", "problems:") when not empty.
std::string reload_text(const dnbridge_ReloadReply& r);
// {"rack", "status" (the word), "message", "file", "applied": [...],
//  "needs_restart": [...], "problems": [...]}
void reload_json(JsonWriter& out, const dnbridge_ReloadReply& r);

}  // namespace dnbridge::dnbctl
