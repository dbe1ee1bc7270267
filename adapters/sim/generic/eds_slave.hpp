#pragma once
// A simulated Group 2 only slave of the predefined master/slave connection
// set whose objects are those an EDS file describes (EdsObjects: Identity,
// Assembly, Parameter, Acknowledge Handler), on the wire every such slave
// shares (Group2Slave: duplicate MAC check, explicit messaging and its
// fragments, Allocate/Release, poll, the Offline Connection Set, delays).
//
// Besides the EDS's objects it has the DeviceNet object (class 0x03,
// instance 1: 1 MAC, 2 baud rate, 5 allocation information, Get only;
// Allocate and Release) and the Connection object (class 0x05,
// connection_object.hpp) of instances 1 (explicit), 2 (poll), 3 (bit-strobe,
// when the EDS's [IO_Info] offers it) and 4 (change of state or cyclic, when
// it offers either).
//
// Poll (instance 2): its produced path names the assembly whose packed data
// answers each poll (EdsObjects::assembly_data), its consumed path the one
// the poll command is unpacked into (EdsObjects::set_assembly_data: the
// member parameters take the outputs). By default the EDS's PollInfo input
// and output; attributes 7/8 are the sizes they pack to. A consumed path
// names an assembly [IO_Info] lists as an output (an OutputN), never an
// input: a poll command must not overwrite the inputs' (read only)
// parameters. A produced path (of any I/O connection) that names an
// [IO_Info] input must name one whose mask lets that connection carry it
// (0x09 otherwise), as a device that produces each input only where its EDS
// says. A poll command shorter than the consumed size is the idle condition (bridge/PROTOCOL.md
// §7): the idle action; Release of an established poll connection is idle
// too; its watchdog expiring, or a duplicate MAC, the fault action. At
// power-up the outputs are zero. The actions are EdsSlaveOptions', unless
// the EDS has the four parameters of this simulator's convention (as the
// example I/O block's EDS does): "Output fault action" and "Output idle
// action" (0: the outputs take the value, 1: they hold) with "Output fault
// value" and "Output idle value" (the output data, from its first byte, the
// rest zero). Then what the master downloads to them is what the outputs do,
// as on a device whose safe state is configured. The idle and fault actions
// act on the assembly the connection consumed (as its path named it), also
// once Release or the watchdog's Auto Delete has deleted it.
//
// I/O data longer than one frame (8 bytes) is not fragmented here: such an
// assembly (or an empty one) cannot be chosen, neither by a path (0x09) nor
// as a default. An [IO_Info] input or output larger than that is no default
// at all: the connection is allocated with no assembly on that side (size
// 0) until the master sets a path that fits; poll_input_assembly() and the
// others say 0.
//
// Change of state / cyclic (instance 4), allocated with choice 0x10 or 0x20
// (0x40 suppresses acknowledgment): produced path the COSInfo's (or
// CyclicInfo's) input, consumed nothing. Once its EPR is set it produces on
// Group 1 message 13 through a CosProducer: on a change of its data
// (inputs_changed(), explicit Sets), no sooner than its inhibit time
// (attribute 17, settable while Configuring), and once per EPR (the
// heartbeat, or the cycle; an EPR set again while Established takes effect
// from the last message), each message acknowledged by the master on
// Group 2 message 2 unless suppressed, retried at the Acknowledge Handler's
// timer up to its retry limit (attributes 1 and 2, read when the connection
// is established). An acknowledgment counts when the Acknowledge Handler's
// COS producing connection instance (attribute 3) is 4; it may carry data,
// which is ignored. The connection's watchdog (4 x EPR) is restarted by each
// acknowledgment and does not run with acknowledgment suppressed (nothing
// consumed): this simulator's reading. It produces exactly while instance 4
// is Established: from its EPR or a Connection Reset out of Timed Out, on
// through a watchdog with Auto Reset, until Release, a timeout that leaves
// it, or the set dropped. Its consumed path (attribute 16) is not settable
// (0x0E).
//
// Bit-strobe (instance 3), allocated with choice 0x04: produced path the
// StrobeInfo's input, consumed the command's 8 bytes (attribute 8; no
// consumed path, 0x0E). Once its EPR is set, each bit-strobe command (Group
// 2 message 0) of the master that owns the set restarts its watchdog and is
// answered at once on Group 1 message 14 with the produced assembly's data;
// the device's bit is kept (strobe_counters()), not applied: the example
// EDS's strobe consumes no output. Timed out or released, it answers none.
#include <cstdint>
#include <optional>

#include "adapters/sim/generic/connection_object.hpp"
#include "adapters/sim/generic/connection_set.hpp"
#include "adapters/sim/generic/cos_producer.hpp"
#include "adapters/sim/generic/eds_objects.hpp"
#include "adapters/sim/generic/group2_slave.hpp"
#include "bridge/profiles/eds/eds_file.hpp"

namespace dnbridge::sim {

// What the outputs (the consumed assembly's parameters) do when the master
// goes idle or away.
enum class OutputAction : std::uint8_t {
  kZero,  // every bit of the assembly 0
  kHold,  // the last values kept
};

struct EdsSlaveOptions {
  std::uint8_t mac = 63;
  std::uint8_t baud = 0;  // DeviceNet object attribute 2: 0 125k, 1 250k, 2 500k
  std::uint32_t serial_number = 1;
  // Unless the EDS has the safe-state parameters of the convention above.
  OutputAction idle_action = OutputAction::kZero;
  OutputAction fault_action = OutputAction::kZero;
  // An idle poll answered with no data rather than the produced data
  // (bridge/PROTOCOL.md §7 leaves it open).
  bool idle_poll_answered_empty = false;
  // Expected packet rates are rounded up to this (bridge/PROTOCOL.md §7).
  Duration timer_resolution = milliseconds(10);
  // False: no member lists (Assembly attributes 1 and 2 answer 0x14), as a
  // device that describes its assemblies only in its EDS.
  bool member_lists = true;
  // The wire's readings and delays; its vendor ID and serial number are the
  // EDS's VendCode and serial_number above.
  Group2Options wire{};
};

class EdsSlave final : public Group2Slave, private ConnectionEvents, private IoAssemblies {
 public:
  EdsSlave(can::FrameSink& sink, profiles::eds::EdsFile file, EdsSlaveOptions options = {},
           Logger log = {});

  devicenet::MacId mac() const noexcept { return mac_; }
  // 255 when no master owns the connection set.
  std::uint8_t owner() const noexcept { return connections_.owner(); }
  const ConnectionSet& connections() const noexcept { return connections_; }
  ConnectionState explicit_state() const noexcept {
    return connections_.explicit_connection().state;
  }
  ConnectionState poll_state() const noexcept { return connections_.poll_connection().state; }
  ConnectionState cos_state() const noexcept { return connections_.cos_connection().state; }
  const EdsSlaveOptions& options() const noexcept { return options_; }

  // The device's objects; a test sets inputs with objects().set_param_value()
  // and then calls inputs_changed().
  EdsObjects& objects() noexcept { return objects_; }
  const EdsObjects& objects() const noexcept { return objects_; }
  // The change-of-state connection's data may have changed: a message now,
  // if it is due.
  void inputs_changed(TimePoint now) noexcept;

  // Whether the change-of-state connection produces: exactly while instance
  // 4 is Established.
  bool cos_producing() const noexcept { return cos_.has_value(); }
  // The change-of-state connection's messages, every connection since
  // power-on added up (produced counts retries too).
  CosProducerCounters cos_counters() const noexcept;
  // The default assemblies of the poll and change-of-state connections, from
  // [IO_Info]; 0 for none, or for one that does not fit a frame.
  std::uint16_t poll_input_assembly() const noexcept { return defaults_.poll_input; }
  std::uint16_t poll_output_assembly() const noexcept { return defaults_.poll_output; }
  std::uint16_t cos_input_assembly() const noexcept { return defaults_.cos_input; }
  std::uint16_t strobe_input_assembly() const noexcept { return defaults_.strobe_input; }

  // The bit-strobe connection (instance 3, where [IO_Info] offers it): each
  // bit-strobe command of the owning master, while it is Established,
  // restarts its watchdog and is answered with its produced assembly on
  // Group 1 message 14. The device's bit is kept, not applied (the EDS's
  // strobe consumes no output).
  struct StrobeCounters {
    std::uint32_t commands = 0;
    std::uint32_t responses = 0;
    bool last_bit = false;
  };
  ConnectionState strobe_state() const noexcept { return connections_.strobe_connection().state; }
  const StrobeCounters& strobe_counters() const noexcept { return strobe_counters_; }

 private:
  // Group2Slave
  devicenet::MacId device_mac() const noexcept override { return mac_; }
  const ConnectionSet& connection_set() const noexcept override { return connections_; }
  ConnectionSet& connection_set() noexcept override { return connections_; }
  void power_up_device(TimePoint now, PowerUpCause cause) noexcept override;
  void advance_device(TimePoint) noexcept override {}
  TimePoint process_deadline() const noexcept override { return kNever; }
  void device_timer(TimePoint now) noexcept override;
  TimePoint device_deadline() const noexcept override;
  std::size_t execute(const devicenet::RequestMessage& request, std::uint8_t requester,
                      TimePoint now, MutableBytes out) noexcept override;
  PendingAction take_pending_action() noexcept override { return PendingAction::kNone; }
  void restore_factory_defaults() noexcept override {}
  PollResult poll(Bytes command, TimePoint now) noexcept override;
  void go_offline(TimePoint now) noexcept override;
  Reply set_mac(std::uint8_t mac) noexcept override;
  bool on_io_message(devicenet::Group2Message message, const can::CanFrame& frame,
                     TimePoint now) noexcept override;

  // ConnectionEvents
  void on_io_established(std::uint16_t instance, TimePoint now) noexcept override;
  void on_io_rate_changed(std::uint16_t instance, TimePoint now) noexcept override;
  void on_io_released(std::uint16_t instance, const Connection& before,
                      TimePoint now) noexcept override;
  void on_io_timed_out(std::uint16_t instance, const Connection& before,
                       TimePoint now) noexcept override;

  // IoAssemblies
  std::uint16_t connection_size(std::uint16_t instance, bool produced) const noexcept override;
  bool assembly_allowed(std::uint16_t instance, bool produced,
                        std::uint16_t assembly) const noexcept override;

  Reply devicenet_object(const devicenet::RequestMessage& r, std::uint8_t requester, TimePoint now,
                         ByteWriter& w) noexcept;
  Reply connection_object(const devicenet::RequestMessage& r, TimePoint now,
                          ByteWriter& w) noexcept;
  // The outputs of the consumed assembly `outputs` (0: none) on idle
  // (`fault` false) or on a fault.
  void apply_output_action(bool fault, std::uint16_t outputs) noexcept;
  // An assembly [IO_Info] lists as an output.
  bool is_output_assembly(std::uint16_t assembly) const noexcept;
  // Whether the connection `instance` may produce `assembly`: as the mask of
  // the [IO_Info] input that names it says (any, for an assembly no input
  // names).
  bool input_carried_by(std::uint16_t assembly, std::uint16_t instance) const noexcept;
  // The convention's parameters, when the EDS has all four (ParamN's N).
  struct SafeStateParams {
    unsigned fault_action = 0, fault_value = 0, idle_action = 0, idle_value = 0;
  };
  std::optional<SafeStateParams> safe_state_params_;
  bool on_strobe(const can::CanFrame& frame, TimePoint now) noexcept;
  static constexpr std::uint16_t kStrobeCommandSize = 8;
  void start_cos(TimePoint now) noexcept;
  void end_cos() noexcept;
  void produce(const std::optional<std::vector<std::uint8_t>>& message, TimePoint now) noexcept;

  // What [IO_Info] offers: the allocation choices and the default
  // assemblies (0: none, or one that does not fit a frame).
  struct IoDefaults {
    std::uint16_t poll_input = 0;
    std::uint16_t poll_output = 0;
    std::uint16_t cos_input = 0;
    std::uint16_t strobe_input = 0;
    std::uint8_t choices = 0;
  };
  static IoDefaults io_defaults(const EdsObjects& objects) noexcept;
  static ConnectionSetOptions connection_options(const EdsSlaveOptions& o,
                                                 const IoDefaults& d) noexcept;

  EdsSlaveOptions options_;
  EdsObjects objects_;
  devicenet::MacId mac_;
  IoDefaults defaults_;
  ConnectionSet connections_;
  std::optional<CosProducer> cos_;
  CosProducerCounters cos_ended_;  // of the connections before the current one
  StrobeCounters strobe_counters_;
};

}  // namespace dnbridge::sim
