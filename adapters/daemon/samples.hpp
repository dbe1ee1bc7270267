#pragma once
// The mapping between the rack model and the IDL types: what each published
// member means is decided here, in one place.
#include <string>
#include <string_view>

#include "adapters/daemon/reload.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/port/port_loop.hpp"
#include "adapters/port/port_publisher.hpp"
#include "bridge/rack/device_rack.hpp"
#include "bridge/rack/explicit_gateway.hpp"
#include "bridge/rack/pump_rack.hpp"
#include "dnbridge.h"

namespace dnbridge::daemon {

// The part of NodeStatus every node has, whatever its profile (identity,
// state, timings, errors, counters): a profile's NodeStatus filler calls it
// first, then fills its own part (safe state, idle reason).
void fill_node_common(dnbridge_NodeStatus& out, std::string_view rack, std::string_view port,
                      const rack::NodeView& v, const port::NodeStatusView& node);

void fill_pump_state(dnbridge_PumpState& out, std::string_view rack, std::string_view port,
                     const rack::PumpView& pump);
void fill_node_status(dnbridge_NodeStatus& out, std::string_view rack, std::string_view port,
                      const rack::PumpView& pump, const port::NodeStatusView& node);
void fill_device_state(dnbridge_DeviceState& out, std::string_view rack, std::string_view port,
                       const rack::DeviceView& device);
void fill_node_status(dnbridge_NodeStatus& out, std::string_view rack, std::string_view port,
                      const rack::DeviceView& device, const port::NodeStatusView& node);
void fill_port_status(dnbridge_PortStatus& out, std::string_view rack,
                      const port::PortStatusView& status);
void fill_explicit_reply(dnbridge_ExplicitReply& out, const rack::ExplicitAnswer& answer);
void fill_bus_scan_reply(dnbridge_BusScanReply& out, std::string_view rack, std::string_view port,
                         const port::BusScanAnswer& answer);

void fill_reload_reply(dnbridge_ReloadReply& out, std::string_view rack, const ReloadCall& call,
                       const ReloadReport& report);

// A command sample's outputs in the form its profile's rack takes them: a
// pump's PumpOutputs; a device's bytes, or its fields when it has none, or
// a malformed command (refused) when it has both.
rack::NodeCommand command_of(const dnbridge_PumpCommand& command);
rack::NodeCommand command_of(const dnbridge_DeviceCommand& command);

// A request sample as the explicit gateway takes it.
rack::ExplicitCall call_of(const dnbridge_ExplicitRequest& request);

// Identity object State (attribute 8), for people.
std::string_view device_state_text(std::uint8_t state);

}  // namespace dnbridge::daemon
