#!/usr/bin/env bash
# Runs one system test inside a Linux kernel of its own that has SocketCAN
# (the machine's own kernel may not), with this machine's filesystem as its
# root: User-Mode Linux where it can run a process, QEMU otherwise. Both give
# the test vcan0 and vcan1 and the same view of the file system
# (guest_init.sh sets the guest up, the same script in either). The test's
# exit status comes back through a file, as neither passes one back. Prints
# which virtual machine was used and why, the test's output, and the
# console on failure.
#   run_in_vm.sh TEST_BINARY GTEST_FILTER WORK_DIR [TIMEOUT_SECONDS]
#
# DNBRIDGE_VM chooses: "auto" (the default) probes User-Mode Linux once per
# boot of this machine (vm.sh; a few seconds, the answer kept beside
# the work directories) and takes QEMU where it cannot run its init (as on
# CPUs with AMX: UML 6.1 mishandles their extended FPU state); "uml" or
# "qemu" forces one (the test suite forces QEMU once, so both stay working).
# Needs the Debian packages of .ci/deps: user-mode-linux; qemu-system-x86,
# linux-image-amd64, busybox-static and cpio; kmod and iproute2.
set -uo pipefail

binary=$1
filter=$2
work=$3
limit=${4:-240}
here=$(cd "$(dirname "$0")" && pwd)
source_dir=$(cd "$here/../.." && pwd)

fail() {
  echo "SYSTEM TEST FAILED ($filter): $*" >&2
  exit 1
}

# The last lines of the programs' logs, which the test prints itself only
# when it gets to its end (not when the machine's time limit stops it).
program_logs() {
  local f
  for f in "$work"/*.log; do
    case "$(basename "$f")" in test.log | console.log) continue ;; esac
    [ -f "$f" ] || continue
    echo "--- $f (last lines)"
    tail -n 30 "$f"
  done
}

[ -x "$binary" ] || fail "test binary $binary not built"
rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)
binary=$(cd "$(dirname "$binary")" && pwd)/$(basename "$binary")
case "$work$binary$here" in
  *[[:space:]]*) fail "paths with white space cannot be passed to the guest's init: $work" ;;
esac

# shellcheck source=tests/system/vm.sh
source "$here/vm.sh"
probe_dir=$(dirname "$work")/vm-probe
choose_vm "$probe_dir" || fail "$vm_reason"
echo "system test runner: $vm_kind${vm_accel:+ ($vm_accel)}: $vm_reason"

# The guest's init: guest_init.sh, with what it needs in a file beside it.
cpu_loop_ms=$(bash "$here/cpu_loop.sh") || fail "cannot time the speed reference loop on this machine"
{
  echo "vm_kind=$vm_kind"
  echo "test_binary=$binary"
  echo "gtest_filter=$filter"
  echo "dds_xml=$source_dir/deploy/cyclonedds/loopback.xml"
  echo "host_loop_ms=$cpu_loop_ms"
} > "$work/guest.env"
can_modules "$vm_kind" "$vm_kernel" > "$work/modules" || fail "$vm_reason"
cat > "$work/init" <<INIT
#!/bin/sh
exec /bin/sh '$here/guest_init.sh' '$work'
INIT
chmod +x "$work/init"

start=$(date +%s)
boot_vm "$work/init" "$work/console.log" "$limit"
vm_status=$?
elapsed=$(( $(date +%s) - start ))

[ -f "$work/test.log" ] && cat "$work/test.log"
[ -f "$work/speed" ] && echo "guest speed: $(cat "$work/speed")"
if [ ! -f "$work/result" ]; then
  program_logs
  echo "--- $vm_kind console ($work/console.log)"
  tail -n 80 "$work/console.log"
  if [ "$vm_status" -eq 124 ] || [ "$vm_status" -eq 137 ]; then
    fail "$vm_kind did not finish within ${limit} s"
  fi
  fail "$vm_kind ended (status $vm_status) without a test result"
fi
status=$(cat "$work/result")
if [ "$status" != 0 ]; then
  echo "--- $vm_kind console ($work/console.log)"
  tail -n 80 "$work/console.log"
  fail "test exit status $status after ${elapsed} s in $vm_kind (logs in $work)"
fi
# A filter that matched nothing passes in GoogleTest: one test must have run.
grep -q '^\[  PASSED  \] 1 test\.' "$work/test.log" || fail "not exactly one test ran for filter $filter"
echo "system test $filter passed in ${elapsed} s ($vm_kind${vm_accel:+, $vm_accel})"
