#pragma once
// What the master must know to bring up a node described by its EDS file
// (profile "eds"): the identity it must show ([Device] vendor, product type,
// product code), the I/O connection's data (the chosen [IO_Info] connection's
// InputN and OutputN: paths and sizes), and the parameters set before the
// connection starts, by their EDS names, each at its link path: read first,
// written only when it differs, read back (devicenet::AttributeSetting).
//
// Safe means configured: a node whose connection has outputs needs its safe
// state given, as the parameters that set its outputs' fault and idle
// actions and values (which ones they are, the EDS's help texts say; no
// standard names them). They are downloaded after the other parameters and
// verified like them. Without them the node is refused, not run on the
// device's factory actions.
#include <memory>
#include <string>
#include <vector>

#include "bridge/common/result.hpp"
#include "bridge/devicenet/master/scan_list.hpp"
#include "bridge/profiles/eds/eds_file.hpp"
#include "bridge/profiles/eds/io_layout.hpp"

namespace dnbridge::profiles::eds {

// A parameter's value as the device holds it (the EDS's minimum, maximum
// and default are in these units; no scaling).
struct ParameterValue {
  std::string name;  // the EDS's ParamN name, any case
  double value = 0;

  friend bool operator==(const ParameterValue&, const ParameterValue&) = default;
};

struct EdsNode {
  ConnectionKind connection = ConnectionKind::kPoll;
  std::vector<ParameterValue> parameters;  // set in this order
  std::vector<ParameterValue> safe_state;  // then these
  // safe_state = "device": the outputs' fault and idle behaviour is the
  // device's own, fixed by its maker; none is written. The parameters the
  // EDS names for it (device_safe_state) are read and kept
  // (devicenet::AttributeSetting::keep_device_value).
  bool safe_state_of_device = false;
  // Change of state or cyclic: the connection's EPR (the heartbeat, or the
  // cycle), its production inhibit time (change of state; none leaves the
  // device's), and whether its messages are acknowledged.
  Duration heartbeat = milliseconds(1000);
  std::optional<Duration> inhibit;
  bool acknowledged = true;

  friend bool operator==(const EdsNode&, const EdsNode&) = default;
};

// The connection's data as the EDS lays it out.
struct NodeIo {
  IoLayout produced;  // the node's inputs (InputN); size 0: none
  IoLayout consumed;  // its outputs (OutputN); size 0: none
};

// The chosen connection's InputN and OutputN; on change of state or cyclic,
// that connection's InputN and the poll connection's OutputN (the master
// commands the outputs on the poll connection beside it). kUnsupported when
// the EDS does not offer the connection (or, then, a poll connection), `why`
// saying so.
Result<NodeIo> node_io(const EdsFile& file, ConnectionKind connection, std::string* why = nullptr);

// The parameter `name` names: its name, or ParamN. Fails (kMalformed), `why`
// saying so after `list` ("parameters: ..."), for a name the EDS does not
// have (with the nearest) or that several parameters share.
Result<const Param*> find_param(const EdsFile& file, std::string_view name, std::string_view list,
                                std::string* why = nullptr);

// The attribute setting that makes the parameter `given` names hold its
// value on the device: its link path, the value in its type and size.
// Fails as find_param, and for a parameter read only, without a link path
// to an attribute, of a string type, or a value outside its type or the
// EDS's limits (a REAL's as single precision).
Result<devicenet::AttributeSetting> parameter_setting(const EdsFile& file,
                                                      const ParameterValue& given,
                                                      std::string_view list,
                                                      std::string* why = nullptr);

// The scan-list profile of `node`. Fails (kUnsupported, kMalformed,
// kOutOfRange), `why` naming the parameter and what is wrong, for: a
// connection the EDS does not offer, a bit-strobe connection that consumes
// an output or produces more than one frame (the master sends no strobe
// outputs), an unknown parameter (with the nearest name), one given twice, one
// read only, one without a link path or of a string type, a value outside
// its type or the EDS's limits, and outputs without a safe state (neither
// safe_state parameters nor safe_state_of_device).
//
// Where the EDS lists the members of the connection's input or output
// assembly, the profile checks the device's member list (Assembly attribute
// 2, shared/seeds/003) against it at start-up (member_check.hpp): a device
// that reports other members is a configuration fault saying which.
Result<devicenet::NodeProfile> make_node_profile(const std::shared_ptr<const EdsFile>& file,
                                                 const EdsNode& node, std::string* why = nullptr);

// The writable, linked parameters whose names speak of a fault or an idle
// state ("fault", "idle", any case) that the node sets in neither list:
// values the device keeps as they are, which may be its factory's. No
// standard names a device's safe-state parameters: for a warning, not a
// refusal.
std::vector<const Param*> safe_state_left_to_device(const EdsFile& file, const EdsNode& node);

// With safe_state = "device", the parameters whose names speak of a fault
// or an idle state, writable or read only, in the EDS's order: `read`, the
// ones the master reads and keeps at start-up (a link path to an attribute,
// 1, 2 or 4 bytes), after the node's parameters; `unread`, the others;
// `written`, those the node sets in `parameters` all the same.
struct DeviceSafeState {
  std::vector<const Param*> read, unread, written;
};
DeviceSafeState device_safe_state(const EdsFile& file, const EdsNode& node);

// The setting that reads the parameter `p` and keeps the device's value
// (keep_device_value: any value of its size); nothing when it has no link
// path to an attribute or is not of 1, 2 or 4 bytes.
std::optional<devicenet::AttributeSetting> kept_setting(const Param& p);

}  // namespace dnbridge::profiles::eds
