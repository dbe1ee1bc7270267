#!/usr/bin/env python3
"""Writes the session seeds of the eds_slave fuzz target: what a master at
MAC 0 sends the example I/O block (or valve manifold) at MAC 1, frame by frame, in the record
format of support/session_records.hpp. The files are committed (corpus/);
run this again after changing a session here. The seeds named cdn127_* are
the cdn127_slave target's (a master bringing up a node at MAC 1), copied.

Usage: make_seeds.py [corpus directory]
"""
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "corpus")

FRAME, TIMER, INPUTS, STOP = 0, 8, 9, 12  # ops; INPUTS is kSetOutputs
MAC = 1
EXPLICIT = 0x400 | MAC << 3 | 4     # Group 2 message 4, explicit request
POLL = 0x400 | MAC << 3 | 5         # Group 2 message 5, poll command
UNCONNECTED = 0x400 | MAC << 3 | 6  # Group 2 message 6, Allocate / Release
DUP_MAC = 0x400 | MAC << 3 | 7      # Group 2 message 7
COS_ACK = 0x400 | MAC << 3 | 2      # Group 2 message 2
STROBE = 0x400 | 0 << 3 | 0         # Group 2 message 0 of the master at MAC 0
OTHER_STROBE = 0x400 | 9 << 3 | 0   # ... of another master
OFFLINE_OWNERSHIP = 0x7EF


class Session:
    def __init__(self):
        self.out = bytearray()

    def record(self, op, ms, can_id=None, data=b""):
        units = round(ms * 10)  # 100 us
        while units > 0xFFFF:
            self.out += bytes([TIMER << 4]) + struct.pack("<H", 0xFFFF)
            units -= 0xFFFF
        self.out += bytes([op << 4 | len(data)]) + struct.pack("<H", units)
        if op == FRAME:
            self.out += struct.pack("<H", can_id)
        self.out += bytes(data)
        return self

    def wait(self, ms):
        return self.record(TIMER, ms)

    def frame(self, can_id, data, ms=1):
        return self.record(FRAME, ms, can_id, bytes(data))

    def request(self, message, ms=2):
        """An explicit request (service byte first), fragmented over 7 bytes."""
        if len(message) <= 7:
            return self.frame(EXPLICIT, [0x00] + message, ms)
        chunks = [message[i:i + 6] for i in range(0, len(message), 6)]
        for n, chunk in enumerate(chunks):
            kind = 0x00 if n == 0 else 0x80 if n == len(chunks) - 1 else 0x40
            self.frame(EXPLICIT, [0x80, kind | n] + chunk, ms)
        return self

    def ack_fragments(self, count, ms=1):
        """The master's acks of a fragmented response's fragments 0..count-1."""
        for n in range(count):
            self.frame(EXPLICIT, [0x80, 0xC0 | n, 0x00], ms)
        return self

    def allocate(self, choice):
        return self.frame(UNCONNECTED, [0x00, 0x4B, 0x03, 0x01, choice, 0x00])

    def release(self, choice):
        return self.frame(UNCONNECTED, [0x00, 0x4C, 0x03, 0x01, choice])

    def set_conn(self, instance, attribute, data):
        return self.request([0x10, 0x05, instance, attribute] + data)

    def epr(self, instance, ms):
        return self.set_conn(instance, 9, list(struct.pack("<H", ms)))

    def inputs(self, di, status, ms=1):
        return self.record(INPUTS, ms, data=bytes([di, status]))


def assembly_path(instance):
    return [0x20, 0x04, 0x24, instance, 0x30, 0x03]


def online():
    # The duplicate MAC check: a request, 1 s, another, 1 s (each window from
    # the timer that ends the one before).
    return Session().wait(1000).wait(1000).wait(10)


SESSIONS = {}

# Poll: identity (a fragmented response, acked), outputs, an idle poll,
# Release.
s = online().allocate(0x03).request([0x0E, 0x01, 0x01, 0x07]).ack_fragments(5)
s.epr(2, 100)
for v in (0x3C, 0x81, 0x00):
    s.frame(POLL, [v, 0x00], 100)
s.frame(POLL, [], 100).frame(POLL, [0x01, 0x02, 0x03], 10)
s.release(0x02).wait(500).release(0x01)
SESSIONS["poll_outputs_idle_release"] = s

# Paths set while Configuring (fragmented requests): outputs consumed, the
# outputs produced (an echo), the inputs refused as consumed; then polls and
# the watchdog's fault.
s = online().allocate(0x03)
s.set_conn(2, 16, assembly_path(150)).set_conn(2, 14, assembly_path(150))
s.set_conn(2, 16, assembly_path(100)).set_conn(2, 12, [0x01])
s.epr(2, 50).frame(POLL, [0x55, 0x00], 20).frame(POLL, [0x66, 0x00], 50).wait(400)
SESSIONS["poll_paths_auto_delete"] = s

# Change of state, acknowledged: inhibit time, changes, heartbeats acked,
# then silence (timed out), a Connection Reset, acks again, Release.
s = online().allocate(0x11).set_conn(4, 17, [10, 0]).epr(4, 100)
s.inputs(0x5A, 0x01).frame(COS_ACK, [])
s.inputs(0x5B, 0x01, 5).inputs(0x5C, 0x01, 20).frame(COS_ACK, [])
for _ in range(3):
    s.frame(COS_ACK, [], 100)
s.wait(600).request([0x05, 0x05, 0x04]).frame(COS_ACK, [], 5)
s.frame(COS_ACK, [], 100).release(0x10)
SESSIONS["cos_acked_timeout_reset"] = s

# Change of state with Auto Reset and no acknowledgment: retries, timeouts,
# a new rate while Established.
s = online().allocate(0x11).set_conn(4, 12, [0x02]).epr(4, 100)
s.inputs(0x01, 0x01).wait(900).epr(4, 50).inputs(0x02, 0x01, 10).wait(500)
s.request([0x0E, 0x2B, 0x01, 0x05])  # Acknowledge Handler's ack list
SESSIONS["cos_auto_reset_new_rate"] = s

# Cyclic with acknowledgment suppressed: a rate, a faster one, Release of
# acknowledge suppression alone (refused), then of the connection.
s = online().allocate(0x61).epr(4, 1000).wait(1500).epr(4, 100).wait(500)
s.release(0x40).release(0x60).release(0x01)
SESSIONS["cyclic_suppressed_rate"] = s

# Poll and change of state together, the master gone: both watchdogs, the
# explicit one last; then a power cycle.
s = online().allocate(0x13).epr(2, 100).epr(4, 100)
s.frame(POLL, [0x0F, 0x00], 10).frame(COS_ACK, [], 5).wait(11000)
s.record(STOP, 1).wait(1000).wait(1000).wait(10).allocate(0x03)
SESSIONS["master_gone_power_cycle"] = s

# Bit-strobe (the valve manifold's; refused by the I/O block): its produced
# path, EPR, commands of its master and of another, a status change, the
# watchdog, a Connection Reset, Release.
s = online().allocate(0x05).set_conn(3, 14, assembly_path(102)).set_conn(3, 16, [])
s.epr(3, 100)
for _ in range(3):
    s.frame(STROBE, [0x02, 0, 0, 0, 0, 0, 0, 0], 50)
s.frame(OTHER_STROBE, [0xFF] * 8, 10).inputs(0x01, 0x00).frame(STROBE, [], 10)
s.wait(500).frame(STROBE, [0] * 8, 10).request([0x05, 0x05, 0x03])
s.frame(STROBE, [0] * 8, 10).release(0x04).frame(STROBE, [0] * 8, 10).release(0x01)
SESSIONS["bit_strobe_commands_timeout_reset"] = s

# A duplicate MAC during the check: Communication Fault; offline ownership
# taken (vendor 65001 = 0xFDE9, serial 0xDB000101).
s = Session().frame(DUP_MAC, [0x00, 0xE9, 0xFD, 0x02, 0x00, 0x00, 0x00], 200)
# [client MAC][allocate 1][vendor LE][serial LE]
s.frame(OFFLINE_OWNERSHIP, [0x00, 0x01, 0xE9, 0xFD, 0x01, 0x01, 0x00, 0xDB], 10)
s.wait(100).allocate(0x03)
SESSIONS["duplicate_mac_offline"] = s


def main():
    os.makedirs(OUT, exist_ok=True)
    for name, session in SESSIONS.items():
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(session.out)
    source = os.path.join(HERE, "..", "cdn127_slave", "corpus")
    for name in sorted(os.listdir(source)):
        with open(os.path.join(source, name), "rb") as f:
            data = f.read()
        with open(os.path.join(OUT, "cdn127_" + name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
