#pragma once
// The master's own identity in duplicate MAC ID messages, unique per host by
// default: two bridges on one bus must not send identical duplicate MAC ID
// responses (a node that sees two identical ones cannot tell them apart).
#include <cstdint>
#include <string>
#include <string_view>

namespace dnbridge::daemon {

// This host's stable identifier: /etc/machine-id (systemd), else the D-Bus
// machine ID, else the host name; empty if none can be read.
std::string read_host_id();

// The serial number a port's master uses when the configuration gives none:
// a hash (FNV-1a, 32 bits) of the host identifier and the port's name, so
// that it stays the same across restarts and differs between hosts and
// between the ports of one host.
std::uint32_t derived_master_serial(std::string_view host_id, std::string_view port);

}  // namespace dnbridge::daemon
