// reload: a rack's bridge reads its configuration file again and applies
// what differs, as `systemctl reload` does on its host (ReloadRequest /
// ReloadReply). The file is checked whole first: one with problems changes
// nothing.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dnbctl/bridges.hpp"
#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/requester.hpp"
#include "adapters/dnbctl/target.hpp"
#include "bridge/common/closest.hpp"

namespace dnbridge::dnbctl {
namespace {

constexpr dds::WaitSet::Token kReloadReplies = 12;
// A reload checks the file and then waits for every port to apply it;
// releasing and configuring changed nodes again takes a few seconds. The
// reply is awaited this long, or --timeout if that is longer.
constexpr Duration kReloadWait = seconds(30);
// A request with no reply yet is written again this often (a bridge that
// matched late; a repeat is the same transaction, never a second reload).
constexpr Duration kRepeatAfter = seconds(5);

// The racks whose bridge is on the domain: by its participant ("dnbridge
// <rack>"), or by a PortStatus of a bridge that is still there.
std::set<std::string> live_racks(Bridges& bridges, const Client& client) {
  bridges.refresh();
  std::set<std::string> racks;
  for (const auto& [rack, hosts] : bridges.live()) racks.insert(rack);
  for (const auto& [key, port] : client.ports()) {
    if (port.alive) racks.insert(key.rack);
  }
  return racks;
}

std::string list_of(const std::set<std::string>& racks) {
  std::string s;
  for (const auto& r : racks) s += fmt::format("{}\"{}\"", s.empty() ? "" : ", ", r);
  return s;
}

// The rack to reload: --rack's, or the only one on the domain. Throws
// CommandError: kNotFound when that rack's bridge (or any, without --rack)
// was not heard within the timeout, kUsage when several racks are there and
// no --rack says which.
std::string choose_rack(Client& client, const GlobalOptions& o) {
  Bridges bridges(client);
  const auto racks = [&] { return live_racks(bridges, client); };
  const Deadline deadline = deadline_after(o.timeout());
  if (!o.rack.empty()) {
    if (client.wait_until(deadline, [&] { return racks().contains(o.rack); })) return o.rack;
    const std::set<std::string> seen = racks();
    const std::vector<std::string_view> names(seen.begin(), seen.end());
    std::string hint;
    if (const auto near = closest(o.rack, names, 3)) {
      hint = fmt::format(" (did you mean \"{}\"?)", *near);
    } else if (!seen.empty()) {
      hint = fmt::format("; the racks on the domain: {}", list_of(seen));
    }
    throw CommandError(Exit::kNotFound,
                       fmt::format("no bridge of rack \"{}\" answered on DDS domain {} within "
                                   "{:g} s{}{}",
                                   o.rack, o.domain, o.timeout_seconds, hint,
                                   seen.empty() ? no_bridge_causes(client, o) : std::string()));
  }
  if (!client.wait_until(deadline, [&] { return !racks().empty(); })) {
    throw CommandError(Exit::kNotFound,
                       fmt::format("no bridge answered on DDS domain {} within {:g} s{}", o.domain,
                                   o.timeout_seconds, no_bridge_causes(client, o)));
  }
  // Other racks' bridges get a moment to be heard before choosing.
  client.wait_until(std::min(deadline, deadline_after(kSettle)), [] { return false; });
  const std::set<std::string> seen = racks();
  if (seen.size() > 1) {
    throw CommandError(Exit::kUsage,
                       fmt::format("there are several racks on DDS domain {} ({}): give --rack",
                                   o.domain, list_of(seen)));
  }
  return *seen.begin();
}

}  // namespace

CLI::App* add_reload(CLI::App& app) {
  return app.add_subcommand(
      "reload",
      "Make a rack's bridge read its configuration file again and apply what differs, as "
      "systemctl reload does on its host: the rack given with --rack, or the only one on the "
      "domain. The whole file is checked first; one with problems changes nothing. Added nodes "
      "start, removed ones are released, nodes whose device settings changed are configured "
      "again (and idle until a new command); every other node keeps polling. Settings that "
      "only a restart changes are listed as such. Prints the bridge's message, the file, and "
      "what was applied, what needs a restart and the problems. The reply is awaited 30 s, or "
      "--timeout if longer. --json gives rack, status (applied, refused, busy, no-file, "
      "incomplete), message, file, applied, needs_restart and problems. Exit 0 only when the "
      "bridge applied the file.");
}

Exit run_reload(const GlobalOptions& o) {
  if (!o.port.empty()) {
    throw CommandError(Exit::kUsage,
                       "reload applies a rack's whole configuration: give --rack, not --port");
  }
  install_interrupt_handlers();
  Client client = make_client(o);
  const std::string rack = choose_rack(client, o);

  Transactions<dnbridge_ReloadRequest, dnbridge_ReloadReply> reloads(client, kReloadReplies,
                                                                     std::span(&rack, 1));
  std::array<dds::Owned<dnbridge_ReloadRequest>, 1> request;
  dds::set_string(request[0]->requester, requester_name());
  request[0]->txid = 1;
  dds::set_string(request[0]->rack, rack);

  const Duration wait = std::max(kReloadWait, o.timeout());
  const Deadline deadline = deadline_after(wait);
  // The bridge is there: its reader of reload requests is found with it,
  // or it has none.
  if (!reloads.await_reader(client, deadline_after(o.timeout()))) {
    throw CommandError(
        Exit::kNotFound,
        fmt::format("no bridge on DDS domain {} takes reload requests (none has a reader of "
                    "dnbridge/ReloadRequest in the rack's partition within {:g} s): the bridge of "
                    "rack \"{}\" is of a version without reload or partitions, or its DDS "
                    "Security permissions do not grant ReloadRequest",
                    o.domain, o.timeout_seconds, rack));
  }
  auto replies = reloads.exchange(client, request, deadline, kRepeatAfter);
  if (!replies[0]) {
    throw CommandError(Exit::kNotFound,
                       fmt::format("no reload reply from the bridge of rack \"{}\" within {:g} s",
                                   rack, std::chrono::duration<double>(wait).count()));
  }

  const dnbridge_ReloadReply& r = replies[0]->data();
  if (o.json) {
    JsonWriter out;
    reload_json(out, r);
    print(out.str() + "\n");
  } else {
    print(reload_text(r));
  }
  if (r.status == dnbridge_RELOAD_APPLIED) return Exit::kOk;
  // On stderr too, for whoever reads only that.
  std::fputs(fmt::format("dnbctl: rack {}: reload {}: {}\n", rack, reload_status_word(r.status),
                         dds::view(r.message))
                 .c_str(),
             stderr);
  return Exit::kFailed;
}

}  // namespace dnbridge::dnbctl
