"""A supervisor written with Eclipse Cyclone DDS 11.0.1 and its Python binding.

From idl/dnbridge.idl and idl/README.md alone: its types are those the
release's own generator makes of the IDL (idlc -l py), found as the package
`dnbridge` on PYTHONPATH, and its QoS are the data-model guide's. None of the
bridge's code, and none of Cyclone DDS 0.10. For the interoperability test
(cyclone11_interop_test.cpp), which runs it with the release's Python beside
the bridge (dnbridge-sim, on Cyclone DDS 0.10).

  python cyclone11_supervisor.py supervise DOMAIN RACK PORT PUMP DEVICE ISSUER
      1. reads PumpState and NodeStatus of pump PUMP (online; its safe state
         known), DeviceState of DEVICE (a node of profile "eds", online,
         its input fields as its EDS names them) and PortStatus of PORT
         (running);
      2. commands pump PUMP on as ISSUER, and sees it in its PumpState;
      3. asks the pump's Identity vendor id (an explicit Get_Attribute_Single)
         and gets the reply, the vendor id its NodeStatus says;
      4. commands the device's Digital outputs (a DeviceCommand by field) and
         sees them in its DeviceState, and asks the rack's configuration read
         again (ReloadRequest: applied) and PORT's bus scanned (BusScanRequest:
         a success, with findings), seeing their replies.
  python cyclone11_supervisor.py former-node-status DOMAIN
      with `dnbridge` the types of tests/interop/former_node_status.idl
      (NodeStatus before its safe state became members of its own): finds
      the bridge's NodeStatus writer and its type, and checks that a reader
      of the former type is not matched to it.

Each step is printed as it passes. Exit status 0 when every step passed;
otherwise 1, after a line "FAIL dnbridge/TOPIC: what did not happen".
"""

import argparse
import os
import socket
import sys
import time

from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication
from cyclonedds.core import (InstanceState, Policy, Qos, ReadCondition, SampleState, ViewState,
                             WaitSet)
from cyclonedds.domain import DomainParticipant
from cyclonedds.dynamic import get_types_for_typeid
from cyclonedds.pub import DataWriter, Publisher
from cyclonedds.sub import DataReader, Subscriber
from cyclonedds.topic import Topic
from cyclonedds.util import duration

# The rack's start-up (the master's duplicate MAC check, each node's
# identity and configuration) and discovery, on a loaded machine.
STATE_BOUND_S = 30.0
# A command's pump state: the bridge's discovery of the command writer, then
# the pump's next poll.
COMMAND_BOUND_S = 15.0
# An explicit request's reply.
REPLY_BOUND_S = 20.0
# The rack's other topics, at once: a device's command (as a pump's), a
# reload and a bus scan (some 8 s: 1 s per silent MAC, eight at a time).
OTHERS_BOUND_S = 30.0
# A commander rewrites its command, a requester its request, this often
# (idl/README.md, "Write again"): a sample written as soon as the writer
# matched can reach the bridge before it has discovered the writer.
REWRITE_PERIOD_S = 1.0
# The former NodeStatus type: after the bridge's writer and its type are
# known here, the time a reader has to (wrongly) match it, and for the
# bridge to report it (it counts a reader unmatched 3 s after discovery).
UNMATCHED_QUIET_S = 8.0

GET_ATTRIBUTE_SINGLE = 0x0E
IDENTITY_CLASS = 1
IDENTITY_VENDOR_ID = 1
# The example I/O block's (deploy/eds) one output field: its eight outputs.
DIGITAL_OUTPUTS = 0x81


class Failed(Exception):
    """A step did not pass: what did not happen, a line per topic, each
    starting with the topic's name."""

    def __init__(self, *lines):
        super().__init__("\n".join(lines))
        self.lines = lines


def say(text):
    print(text, flush=True)


def rack_partition(rack):
    return "dnbridge/" + rack


# idl/README.md, "State topics": reliable, transient-local, keep-last 1,
# destination order by source timestamp; in the default partition.
STATE_QOS = Qos(
    Policy.Reliability.Reliable(duration(milliseconds=100)),
    Policy.Durability.TransientLocal,
    Policy.History.KeepLast(1),
    Policy.DestinationOrder.BySourceTimestamp,
)

# idl/README.md, "PumpCommand": reliable, volatile, keep-last 1, exclusive
# ownership with a strength, automatic liveliness with a lease (2 s: the
# bridge refuses leases over its bound, and infinite ones), instances only
# unregistered when the writer goes.
COMMAND_STRENGTH = 10
COMMAND_LEASE = duration(seconds=2)
COMMAND_QOS = Qos(
    Policy.Reliability.Reliable(duration(milliseconds=100)),
    Policy.Durability.Volatile,
    Policy.History.KeepLast(1),
    Policy.Ownership.Exclusive,
    Policy.OwnershipStrength(COMMAND_STRENGTH),
    Policy.Liveliness.Automatic(COMMAND_LEASE),
    Policy.WriterDataLifecycle(autodispose=False),
    Policy.DestinationOrder.BySourceTimestamp,
)

# idl/README.md, "ExplicitRequest/ExplicitReply": requests reliable,
# volatile, keep-all; replies read reliable, transient-local, keep-all.
REQUEST_QOS = Qos(
    Policy.Reliability.Reliable(duration(milliseconds=100)),
    Policy.Durability.Volatile,
    Policy.History.KeepAll,
)
REPLY_QOS = Qos(
    Policy.Reliability.Reliable(duration(milliseconds=100)),
    Policy.Durability.TransientLocal,
    Policy.History.KeepAll,
)


def matched_writers(reader):
    return reader.get_subscription_matched_status().current_count


def matched_readers(writer):
    return writer.get_publication_matched_status().current_count


class Rewritten:
    """A sample a writer writes again every REWRITE_PERIOD_S (idl/README.md,
    "Write again": a commander its command, a requester its request until
    answered; a request written again is the same transaction)."""

    def __init__(self, writer, sample):
        self.writer = writer
        self.sample = sample
        self.written = None

    def __call__(self):
        if self.written is None or time.monotonic() - self.written >= REWRITE_PERIOD_S:
            self.writer.write(self.sample)
            self.written = time.monotonic()

    def unmatched(self, topic):
        return f"dnbridge/{topic}: its writer had {matched_readers(self.writer)} reader(s) matched"


class Wanted:
    """A sample of one reader's topic that a step waits for."""

    def __init__(self, reader, topic, what, accept, describe):
        self.reader = reader
        self.topic = topic
        self.what = what  # for the failure message: "PumpState of A 1 online"
        self.accept = accept  # sample -> bool
        self.describe = describe  # sample -> str, printed when it came
        self.sample = None
        self.seen = 0  # valid samples of the topic taken
        self.last = None

    def offer(self, sample):
        self.seen += 1
        self.last = sample
        if self.sample is None and self.accept(sample):
            self.sample = sample
            say(f"dnbridge/{self.topic}: {self.describe(sample)}")


def await_all(participant, wanted, bound_s, writing=()):
    """Takes the readers' samples until each of `wanted` came, for at most
    `bound_s`, meanwhile writing each of `writing` (Rewritten) again when
    due. Raises Failed naming each topic whose sample did not come, and each
    topic written whose writer had no reader."""
    waitset = WaitSet(participant)
    conditions = {}
    for w in wanted:
        if w.reader not in conditions:
            c = ReadCondition(w.reader, SampleState.NotRead | ViewState.Any | InstanceState.Any)
            waitset.attach(c)
            conditions[w.reader] = c
    deadline = time.monotonic() + bound_s
    while True:
        for reader, condition in conditions.items():
            for sample in reader.take(N=256, condition=condition):
                if not sample.sample_info.valid_data:
                    continue
                for w in wanted:
                    if w.reader is reader:
                        w.offer(sample)
        missing = [w for w in wanted if w.sample is None]
        if not missing:
            return
        left = deadline - time.monotonic()
        if left <= 0:
            not_come = (f"dnbridge/{w.topic}: no {w.what} within {bound_s:.0f} s (writers "
                        f"matched: {matched_writers(w.reader)}, samples taken: {w.seen}"
                        + (f"; the last was {w.last})" if w.last is not None else ")")
                        for w in missing)
            unread = (r.unmatched(t) for t, r in writing if matched_readers(r.writer) == 0)
            raise Failed(*not_come, *unread)
        for _, r in writing:
            r()
        waitset.wait(duration(seconds=min(left, REWRITE_PERIOD_S)))


def supervise(args):
    import dnbridge

    rack, port, pump, device, issuer = args.rack, args.port, args.pump, args.device, args.issuer
    participant = DomainParticipant(args.domain, qos=Qos(Policy.EntityName("cyclone11 " + issuer)))
    requester = f"cyclone11-supervisor@{socket.gethostname()}:{os.getpid()}"

    def node(s, mac):
        return s.rack == rack and s.port == port and s.mac == mac

    def field(f):  # a DeviceField: its value with its EDS's scaling and units, its CIP type
        return f"{f.name} = {f.shown:g}{' ' + f.units if f.units else ''} ({f.type})"

    def topic(name):
        return Topic(participant, "dnbridge/" + name, getattr(dnbridge, name))

    # 1. The state topics, in the default partition.
    say(f"step 1: the state of rack {rack} (within {STATE_BOUND_S:.0f} s)")
    pumps = DataReader(participant, topic("PumpState"), qos=STATE_QOS)
    devices = DataReader(participant, topic("DeviceState"), qos=STATE_QOS)
    nodes = DataReader(participant, topic("NodeStatus"), qos=STATE_QOS)
    ports = DataReader(participant, topic("PortStatus"), qos=STATE_QOS)
    pump_state = Wanted(
        pumps, "PumpState", f"PumpState of {port} {pump} online",
        lambda s: node(s, pump) and s.online,
        lambda s: f"{rack} {port} {s.mac} {s.name} online, pump_on={s.pump_on}, "
        f"outputs_idle={s.outputs_idle} ({s.idle_reason or 'commanded by ' + s.commanded_by})")
    device_state = Wanted(
        devices, "DeviceState", f"DeviceState of {port} {device} online with its input fields",
        lambda s: node(s, device) and s.online and s.inputs_valid and len(s.input_fields) > 0,
        lambda s: f"{rack} {port} {s.mac} {s.name} ({s.product}) online, inputs "
        f"{bytes(s.inputs).hex()}: {', '.join(field(f) for f in s.input_fields)}")
    node_status = Wanted(
        nodes, "NodeStatus", f"NodeStatus of {port} {pump} online with its safe state known",
        lambda s: node(s, pump) and s.state == dnbridge.NodeLifecycle.NODE_ONLINE
        and s.safe_state_known,
        lambda s: f"{rack} {port} {s.mac} {s.name} {s.state.name}, {s.product_name} of vendor "
        f"{s.vendor_id}, safe state {s.safe_state_source.name}: {s.safe_state_text}, "
        f"{s.counters.polls} polls")
    port_status = Wanted(
        ports, "PortStatus", f"PortStatus of {port} running",
        lambda s: s.rack == rack and s.port == port
        and s.state == dnbridge.PortLifecycle.PORT_RUNNING,
        lambda s: f"{rack} {s.port} {s.state.name} on {s.can_interface}, "
        f"{s.nodes_online}/{s.nodes_configured} nodes online")
    await_all(participant, [pump_state, device_state, node_status, port_status], STATE_BOUND_S)

    # What is for the rack, in its partition: commands, requests, replies.
    publisher = Publisher(participant, qos=Qos(Policy.Partition([rack_partition(rack)])))
    subscriber = Subscriber(participant, qos=Qos(Policy.Partition([rack_partition(rack)])))

    # 2. A pump commanded.
    say(f"step 2: pump {port} {pump} commanded on by {issuer!r} (within {COMMAND_BOUND_S:.0f} s)")
    command = Rewritten(
        DataWriter(publisher, topic("PumpCommand"), qos=COMMAND_QOS),
        dnbridge.PumpCommand(rack=rack, port=port, mac=pump, pump_on=True, n2_ballast_on=False,
                             analog_output_raw=0, issuer=issuer))
    commanded = Wanted(
        pumps, "PumpState", f"PumpState of {port} {pump} with pump_on and commanded_by {issuer!r}",
        lambda s: node(s, pump) and s.online and s.pump_on and s.commanded_by == issuer,
        lambda s: f"{rack} {port} {s.mac} pump_on={s.pump_on}, commanded_by {s.commanded_by!r} "
        f"(PumpCommand of strength {COMMAND_STRENGTH}, lease 2 s)")
    await_all(participant, [commanded], COMMAND_BOUND_S, [("PumpCommand", command)])

    # 3. An explicit Get of the pump's Identity vendor id.
    say(f"step 3: ExplicitRequest Get_Attribute_Single of class {IDENTITY_CLASS} instance 1 "
        f"attribute {IDENTITY_VENDOR_ID} of {port} {pump} (within {REPLY_BOUND_S:.0f} s)")
    request = Rewritten(
        DataWriter(publisher, topic("ExplicitRequest"), qos=REQUEST_QOS),
        dnbridge.ExplicitRequest(
            requester=requester, txid=1, command=dnbridge.COMMAND_EXECUTE, rack=rack, port=port,
            mac=pump, service=GET_ATTRIBUTE_SINGLE, class_id=IDENTITY_CLASS, instance_id=1,
            has_attribute=True, attribute_id=IDENTITY_VENDOR_ID, data=[]))
    replies = DataReader(subscriber, topic("ExplicitReply"), qos=REPLY_QOS)
    reply = Wanted(
        replies, "ExplicitReply", f"ExplicitReply to {requester} txid 1",
        lambda s: s.requester == requester and s.txid == 1
        and s.status != dnbridge.STATUS_IN_PROGRESS,
        lambda s: f"{s.requester} txid {s.txid} status {s.status}, general status "
        f"{s.general_status}, data {bytes(s.data).hex()} ({s.message})")
    await_all(participant, [reply], REPLY_BOUND_S, [("ExplicitRequest", request)])
    request.writer.unregister_instance(request.sample)
    r = reply.sample
    vendor = node_status.sample.vendor_id.to_bytes(2, "little")
    if r.status != dnbridge.STATUS_SUCCESS or r.general_status != 0 or bytes(r.data) != vendor:
        raise Failed(
            f"dnbridge/ExplicitReply: status {r.status}, general status {r.general_status}, data "
            f"{bytes(r.data).hex()}: expected status {dnbridge.STATUS_SUCCESS} (success), general "
            f"status 0 and the vendor id NodeStatus says, {vendor.hex()}")

    # 4. The rack's other topics, at once: the device commanded by a field,
    # the configuration read again (the same file: nothing to apply), the
    # port's bus scanned.
    say(f"step 4: DeviceCommand, ReloadRequest and BusScanRequest (within {OTHERS_BOUND_S:.0f} s)")
    device_command = Rewritten(
        DataWriter(publisher, topic("DeviceCommand"), qos=COMMAND_QOS),
        dnbridge.DeviceCommand(rack=rack, port=port, mac=device, outputs=[],
                               fields=[dnbridge.DeviceFieldValue(name="Digital outputs",
                                                                 value=DIGITAL_OUTPUTS)],
                               issuer=issuer))
    device_commanded = Wanted(
        devices, "DeviceState", f"DeviceState of {port} {device} with its Digital outputs "
        f"{DIGITAL_OUTPUTS:#x} commanded by {issuer!r}",
        lambda s: node(s, device) and s.online and not s.outputs_idle and s.commanded_by == issuer
        and [(f.name, f.value) for f in s.output_fields] == [("Digital outputs", DIGITAL_OUTPUTS)],
        lambda s: f"{rack} {port} {s.mac} outputs {bytes(s.outputs).hex()}: "
        f"{', '.join(field(f) for f in s.output_fields)}, commanded_by {s.commanded_by!r}")
    reload = Rewritten(
        DataWriter(publisher, topic("ReloadRequest"), qos=REQUEST_QOS),
        dnbridge.ReloadRequest(requester=requester, txid=2, rack=rack))
    reloaded = Wanted(
        DataReader(subscriber, topic("ReloadReply"), qos=REPLY_QOS), "ReloadReply",
        f"ReloadReply to {requester} txid 2, applied",
        lambda s: s.requester == requester and s.txid == 2
        and s.status == dnbridge.RELOAD_APPLIED and len(s.problems) == 0,
        lambda s: f"{s.requester} txid {s.txid} status {s.status} ({s.message}), "
        f"{len(s.applied)} change(s) applied")
    scan = Rewritten(
        DataWriter(publisher, topic("BusScanRequest"), qos=REQUEST_QOS),
        dnbridge.BusScanRequest(requester=requester, txid=3, rack=rack, port=port))
    scanned = Wanted(
        DataReader(subscriber, topic("BusScanReply"), qos=REPLY_QOS), "BusScanReply",
        f"BusScanReply to {requester} txid 3, a success with findings",
        lambda s: s.requester == requester and s.txid == 3
        and s.status == dnbridge.STATUS_SUCCESS and len(s.findings) > 0,
        lambda s: f"{s.requester} txid {s.txid} {s.rack} {s.port} status {s.status}, "
        f"{len(s.findings)} MACs asked in {s.duration_ms} ms, "
        f"{sum(f.found == dnbridge.FOUND_NO_ANSWER for f in s.findings)} without an answer")
    await_all(participant, [device_commanded, reloaded, scanned], OTHERS_BOUND_S,
              [("DeviceCommand", device_command), ("ReloadRequest", reload),
               ("BusScanRequest", scan)])
    reload.writer.unregister_instance(reload.sample)
    scan.writer.unregister_instance(scan.sample)
    say("supervisor: every step passed")


def former_node_status(args):
    import dnbridge

    participant = DomainParticipant(args.domain,
                                    qos=Qos(Policy.EntityName("cyclone11 former NodeStatus")))
    publications = BuiltinDataReader(participant, BuiltinTopicDcpsPublication)
    reader = DataReader(participant, Topic(participant, "dnbridge/NodeStatus", dnbridge.NodeStatus),
                        qos=STATE_QOS)

    # The bridge's NodeStatus writer, as discovered here.
    say(f"the bridge's NodeStatus writer (within {STATE_BOUND_S:.0f} s)")
    waitset = WaitSet(participant)
    condition = ReadCondition(publications,
                              SampleState.NotRead | ViewState.Any | InstanceState.Alive)
    waitset.attach(condition)
    deadline = time.monotonic() + STATE_BOUND_S
    writer = None
    while writer is None:
        for p in publications.take(N=256, condition=condition):
            if p.topic_name == "dnbridge/NodeStatus" and p.participant_key != participant.guid:
                writer = p
        left = deadline - time.monotonic()
        if writer is None and left <= 0:
            raise Failed(f"dnbridge/NodeStatus: no writer discovered within {STATE_BOUND_S:.0f} s")
        if writer is None:
            waitset.wait(duration(seconds=left))
    if writer.type_id is None:
        raise Failed("dnbridge/NodeStatus: the bridge's writer offers no type information: a "
                     "reader of another type of that name would be matched, and misread its "
                     "samples")
    # Its type, through the type lookup service: known here from then on.
    try:
        bridge_type, _ = get_types_for_typeid(participant, writer.type_id, duration(seconds=10))
    except Exception as e:  # the binding's DDSException, or its own errors of type building
        raise Failed(f"dnbridge/NodeStatus: the bridge's writer's type not resolved over the type "
                     f"lookup service: {e}") from None
    theirs = set(bridge_type.__annotations__)
    ours = set(dnbridge.NodeStatus.__annotations__)
    say(f"dnbridge/NodeStatus: the bridge's writer has type {writer.type_name}; members only it "
        f"has: {', '.join(sorted(theirs - ours))}; only the former type has: "
        f"{', '.join(sorted(ours - theirs))}")
    # Matching needs no data, and the writer's type is known here: a reader
    # to be matched would be by now.
    until = time.monotonic() + UNMATCHED_QUIET_S
    while time.monotonic() < until:
        status = reader.get_subscription_matched_status()
        samples = [s for s in reader.take(N=256) if s.sample_info.valid_data]
        if status.total_count > 0 or samples:
            raise Failed(f"dnbridge/NodeStatus: a reader of the former type was matched to the "
                         f"bridge's writer ({status.total_count} match(es), {len(samples)} "
                         f"sample(s))")
        time.sleep(0.1)
    say(f"dnbridge/NodeStatus: a reader of the former type not matched in "
        f"{UNMATCHED_QUIET_S:.0f} s, as it must not be")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    modes = parser.add_subparsers(dest="mode", required=True)
    s = modes.add_parser("supervise")
    s.add_argument("domain", type=int)
    s.add_argument("rack")
    s.add_argument("port")
    s.add_argument("pump", type=int)
    s.add_argument("device", type=int)
    s.add_argument("issuer")
    f = modes.add_parser("former-node-status")
    f.add_argument("domain", type=int)
    args = parser.parse_args()
    try:
        if args.mode == "supervise":
            supervise(args)
        else:
            former_node_status(args)
    except Failed as e:
        for line in e.lines:
            say(f"FAIL {line}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
