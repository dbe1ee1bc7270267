// scan: what is on a port's bus. The bridge asks the MACs its scan list
// does not have (BusScanRequest / BusScanReply); the configured nodes are
// as the bridge reports them (NodeStatus). One row per node found; for an
// unconfigured CDN127, the configuration lines that would add it.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <optional>
#include <span>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/states.hpp"
#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/record.hpp"
#include "adapters/dnbctl/requester.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::dnbctl {
namespace {

namespace cdn127 = profiles::cdn127;

constexpr dds::WaitSet::Token kScanReplies = 11;
// A scan asks up to 63 MACs, eight at a time, 1 s for a silent one: about
// 8 s; a node that answers takes longer. The reply is awaited this long, or
// --timeout if that is longer.
constexpr Duration kScanWait = seconds(60);
// A request with no reply yet is written again this often (a bridge that
// matched late; the same transaction joins the same scan).
constexpr Duration kRepeatAfter = seconds(5);

constexpr std::uint8_t kStatusSuccess = dnbridge_STATUS_SUCCESS;

struct PortScan {
  PortKey key;
  std::uint8_t master_mac = 0;
  std::optional<dds::Sample<dnbridge_BusScanReply>> reply;
};

std::span<const dnbridge_ScanFinding> findings_of(const dnbridge_BusScanReply& r) {
  if (r.findings._buffer == nullptr) return {};
  return {r.findings._buffer, r.findings._length};
}

bool is_cdn127(const dnbridge_ScanFinding& f) {
  return f.vendor_id == cdn127::kVendorId && f.product_type == cdn127::kProductType &&
         f.product_code == cdn127::kProductCode;
}

// The lines that add an unconfigured CDN127 to the rack configuration,
// under its port's [[port]] table (the bridge's only profile is the
// CDN127's: nothing is suggested for another device).
std::string configuration_lines(const dnbridge_ScanFinding& f) {
  return fmt::format("  [[port.node]]\n  mac = {}\n  name = \"node-{}\"\n  serial = 0x{:08X}\n",
                     f.mac, f.mac, f.serial_number);
}

std::string revision_text(std::uint8_t major, std::uint8_t minor) {
  return fmt::format("{}.{}", major, minor);
}

// The identity columns, from a NodeStatus or a finding.
void identity_fields(Record& r, std::uint16_t vendor, std::uint16_t type, std::uint16_t code,
                     std::uint8_t major, std::uint8_t minor, std::uint32_t serial,
                     std::string_view product) {
  const bool known = vendor != 0 || type != 0 || code != 0;
  r.add("vendor", known ? std::to_string(vendor) : "", "vendor_id", known ? Json(vendor) : Json())
      .add("type", known ? std::to_string(type) : "", "product_type", known ? Json(type) : Json())
      .add("code", known ? std::to_string(code) : "", "product_code", known ? Json(code) : Json())
      .add("revision", known ? revision_text(major, minor) : "",
           {{"major_revision", known ? Json(major) : Json()},
            {"minor_revision", known ? Json(minor) : Json()}})
      .add("serial", known ? fmt::format("0x{:08X}", serial) : "", "serial_number",
           known ? Json(serial) : Json())
      .add("product", std::string(product), "product_name",
           known ? Json(std::string(product)) : Json());
}

Record configured_record(const PortKey& port, const NodeRow& row) {
  const dnbridge_NodeStatus& n = *row.node;
  const bool online = node_online(row);
  Record r;
  r.json("rack", port.rack)
      .json("port", port.port)
      .add("mac", std::to_string(n.mac), "mac", n.mac)
      .add("found", fmt::format("configured, {}", online ? "online" : dds::name_of(n.state)),
           "found", "configured")
      .json("configured", true)
      .json("state", online ? "online" : std::string(dds::name_of(n.state)))
      .add("name", std::string(dds::view(n.name)), "name", std::string(dds::view(n.name)));
  // What the bridge read from the device when it last identified it.
  identity_fields(r, n.vendor_id, n.product_type, n.product_code, n.major_revision,
                  n.minor_revision, n.serial_number, dds::view(n.product_name));
  r.add("detail", online ? "" : std::string(dds::view(n.reason)), "detail",
        online ? "" : std::string(dds::view(n.reason)));
  return r;
}

Record finding_record(const PortKey& port, const dnbridge_ScanFinding& f) {
  const bool identified = f.found == dnbridge_FOUND_IDENTIFIED;
  Record r;
  r.json("rack", port.rack)
      .json("port", port.port)
      .add("mac", std::to_string(f.mac), "mac", f.mac)
      .add("found",
           identified ? std::string("unconfigured")
                      : fmt::format("unconfigured, {}", dds::found_name(f.found)),
           "found", std::string(dds::found_name(f.found)))
      .json("configured", false)
      .add("name", "", "name", Json());
  if (identified) {
    identity_fields(r, f.vendor_id, f.product_type, f.product_code, f.major_revision,
                    f.minor_revision, f.serial_number, dds::view(f.product_name));
  } else {
    identity_fields(r, 0, 0, 0, 0, 0, 0, "");
  }
  std::string detail(dds::view(f.detail));
  if (identified && !is_cdn127(f)) {
    detail = "not a CDN127, the one device dnbridge has a profile for" +
             (detail.empty() ? "" : "; " + detail);
  }
  r.add("detail", detail, "detail", detail);
  if (identified && is_cdn127(f)) r.json("suggested_configuration", configuration_lines(f));
  return r;
}

bool found(const dnbridge_ScanFinding& f) {
  return f.found != dnbridge_FOUND_NO_ANSWER && f.found != dnbridge_FOUND_NOT_ASKED;
}

// What a port's scan reply found: its rows (over the configured ones at
// the same MACs), its port record, its summary line and the configuration
// lines of the CDN127s found unconfigured. True when the scan succeeded.
bool take_reply(const PortKey& key, const dnbridge_BusScanReply& r,
                std::map<unsigned, Record>& by_mac, Record& port, std::string& summary,
                std::string& suggestions) {
  std::vector<Json> silent;
  std::string port_suggestions;
  for (const auto& f : findings_of(r)) {
    if (!found(f)) {
      if (f.found == dnbridge_FOUND_NO_ANSWER) silent.emplace_back(unsigned{f.mac});
      continue;
    }
    by_mac.insert_or_assign(f.mac, finding_record(key, f));
    if (f.found == dnbridge_FOUND_IDENTIFIED && is_cdn127(f)) {
      port_suggestions += configuration_lines(f) + "\n";
    }
  }
  port.json("status", r.status)
      .json("message", std::string(dds::view(r.message)))
      .json("duration_ms", r.duration_ms)
      .json("age_ms", r.age_ms)
      .json("silent_macs", Json::values(silent));
  summary +=
      fmt::format("rack {}, {}; {} MACs silent\n", key.rack, dds::view(r.message), silent.size());
  if (!port_suggestions.empty()) {
    suggestions += fmt::format(
        "# Found on port \"{}\" of rack \"{}\", not configured: under "
        "its [[port]] table in the rack configuration,\n",
        key.port, key.rack);
    suggestions += port_suggestions;
  }
  return r.status == kStatusSuccess;
}

}  // namespace

CLI::App* add_scan(CLI::App& app) {
  return app.add_subcommand(
      "scan",
      "What is on the bus of each port (--port P for one): every node the bridge polls, and what "
      "answers at the other MAC IDs, which the bridge asks once each (Allocate of the explicit "
      "connection, the Identity object, Release; never a node of its scan list, never one "
      "another master holds). Each row says whether the node is configured; for an "
      "unconfigured CDN127 found, the configuration lines that would add it follow the table. A "
      "scan takes some 8 s (the reply is awaited 60 s, or --timeout if longer); a port scanned "
      "within the last 30 s answers with that scan. --json "
      "gives one record per node found (mac, vendor_id, product_type, product_code, "
      "serial_number, product_name, configured, ...) and each port's scan.");
}

Exit run_scan(const GlobalOptions& o) {
  install_interrupt_handlers();
  Client client = make_client(o);
  gather(
      client, o, [&] { return any_port(client, o); }, [&] { return nodes_missing(client, o); });

  const std::string requester = requester_name();
  std::vector<PortScan> scans;
  std::vector<dds::Owned<dnbridge_BusScanRequest>> requests;
  std::vector<std::string> racks;
  for (const auto& [key, port] : client.ports()) {
    if (!o.matches(key.rack, key.port) || !port.alive) continue;
    if (std::find(racks.begin(), racks.end(), key.rack) == racks.end()) racks.push_back(key.rack);
    scans.push_back({key, port.data->master_mac, std::nullopt});
    dds::Owned<dnbridge_BusScanRequest>& request = requests.emplace_back();
    dds::set_string(request->requester, requester);
    request->txid = static_cast<std::uint32_t>(requests.size());
    dds::set_string(request->rack, key.rack);
    dds::set_string(request->port, key.port);
  }
  if (scans.empty()) {
    throw CommandError(Exit::kNotFound, "no port with a live bridge to scan");
  }
  Transactions<dnbridge_BusScanRequest, dnbridge_BusScanReply> transactions(client, kScanReplies,
                                                                            racks);

  const Duration wait = std::max(kScanWait, o.timeout());
  const Deadline deadline = deadline_after(wait);
  // A bridge that matches later gets the repeats.
  (void)transactions.await_reader(client, deadline_after(o.timeout()));
  auto replies = transactions.exchange(client, requests, deadline, kRepeatAfter);
  bool answered = true;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    scans[i].reply = std::move(replies[i]);
    answered = answered && scans[i].reply.has_value();
  }

  // The rows: per port, the configured nodes, then what the scan found.
  const std::vector<NodeRow> nodes = node_rows(client, o);
  std::vector<Record> rows;
  std::vector<Record> port_records;
  std::string suggestions;
  std::string summary;
  bool all_ok = answered;
  for (const auto& s : scans) {
    std::map<unsigned, Record> by_mac;
    Record master;
    master.json("rack", s.key.rack)
        .json("port", s.key.port)
        .add("mac", std::to_string(s.master_mac), "mac", s.master_mac)
        .add("found", "this bridge (the master)", "found", "master")
        .json("configured", true);
    by_mac.emplace(s.master_mac, std::move(master));
    for (const auto& row : nodes) {
      if (dds::view(row.node->rack) != s.key.rack || dds::view(row.node->port) != s.key.port) {
        continue;
      }
      by_mac.insert_or_assign(row.node->mac, configured_record(s.key, row));
    }
    Record port;
    port.json("rack", s.key.rack).json("port", s.key.port);
    if (!s.reply) {
      all_ok = false;
      port.json("status", Json()).json("message", "no reply from the bridge");
      summary += fmt::format(
          "rack {} port {}: no reply from the bridge within {:.0f} s: the "
          "configured nodes only\n",
          s.key.rack, s.key.port, std::chrono::duration<double>(wait).count());
    } else {
      all_ok = take_reply(s.key, s.reply->data(), by_mac, port, summary, suggestions) && all_ok;
    }
    port_records.push_back(std::move(port));
    for (auto& [mac, record] : by_mac) rows.push_back(std::move(record));
  }

  if (o.json) {
    JsonWriter out;
    Record doc;
    doc.json("nodes", Json::array(std::move(rows))).json("ports", Json::array(port_records));
    doc.write(out);
    print(out.str() + "\n");
  } else {
    static constexpr std::string_view kColumns[] = {"mac",     "found", "name",     "vendor",
                                                    "type",    "code",  "revision", "serial",
                                                    "product", "detail"};
    std::string text = table(kColumns, rows);
    text += "\n" + summary;
    if (!suggestions.empty()) text += "\n" + suggestions;
    print(text);
  }
  if (!answered) {
    std::fprintf(stderr, "dnbctl: not every port's bridge answered the scan within %.0f s\n",
                 std::chrono::duration<double>(wait).count());
    return Exit::kNotFound;
  }
  return all_ok ? Exit::kOk : Exit::kFailed;
}

}  // namespace dnbridge::dnbctl
