#!/usr/bin/env bash
# Runs the example supervisor against `dnbridge-sim --simulate`, both on this
# host only, with a discovery tag of their own so other DDS programs on the
# host do not join in. Passes when the supervisor saw the rack, commanded a
# pump, saw the echo, and saw the pump go idle once it left.
# Usage: run_example.sh DNBRIDGE_SIM EXAMPLE_SUPERVISOR
set -euo pipefail
bridge="$1"
supervisor="$2"
tag="dnbridge-example-$$"
export CYCLONEDDS_URI="<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>50</MaxAutoParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers><Tag>${tag}</Tag></Discovery></Domain></CycloneDDS>"

"$bridge" --simulate --log-level warn &
bridge_pid=$!
trap 'kill -TERM "$bridge_pid" 2>/dev/null || true' EXIT

# The supervisor waits (up to 5 s) for the pump's state: the bridge needs
# about 2 s to check its MAC and bring the rack online.
status=0
"$supervisor" sim-rack A 4 2 || status=$?

kill -TERM "$bridge_pid"
wait "$bridge_pid" || { echo "dnbridge did not stop cleanly"; exit 1; }
trap - EXIT
exit "$status"
