#!/usr/bin/env bash
# Runs one system test inside a User-Mode Linux kernel that has SocketCAN
# (the machine's own kernel may not): boots `linux` with this machine's
# filesystem as root, uml_init.sh as init, and reads the test's exit status
# from a file (UML does not pass an exit status back). Prints the test's
# output, and the UML console on failure.
#   run_in_uml.sh TEST_BINARY GTEST_FILTER WORK_DIR [TIMEOUT_SECONDS]
# Needs the Debian packages user-mode-linux, kmod, iproute2 (bash .ci/deps).
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

uml=$(command -v linux.uml || command -v linux || true)
[ -n "$uml" ] || fail "User-Mode Linux is not installed (the 'linux' program of the user-mode-linux package): run bash .ci/deps"
modules=$(ls -d /usr/lib/uml/modules/*/kernel/net/can 2>/dev/null | head -n 1)
[ -n "$modules" ] || fail "the UML CAN modules are missing (/usr/lib/uml/modules/*/kernel/net/can): run bash .ci/deps"
for tool in ip insmod halt; do
  PATH=$PATH:/usr/sbin:/sbin command -v "$tool" >/dev/null || fail "$tool is not installed: run bash .ci/deps"
done
[ -x "$binary" ] || fail "test binary $binary not built"

rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)
binary=$(cd "$(dirname "$binary")" && pwd)/$(basename "$binary")

# The kernel starts init without arguments: a script of our own passes them.
cat > "$work/init" <<INIT
#!/bin/sh
exec /bin/sh '$here/uml_init.sh' '$work' '$binary' '$filter' '$source_dir/deploy/cyclonedds/loopback.xml'
INIT
chmod +x "$work/init"

start=$(date +%s)
timeout --kill-after=10 "$limit" "$uml" mem=512M rootfstype=hostfs rootflags=/ rw \
  init="$work/init" con=null con0=fd:0,fd:1 </dev/null >"$work/console.log" 2>&1
uml_status=$?
elapsed=$(( $(date +%s) - start ))

[ -f "$work/test.log" ] && cat "$work/test.log"
if [ ! -f "$work/result" ]; then
  echo "--- UML console ($work/console.log)"
  tail -n 80 "$work/console.log"
  if [ "$uml_status" -eq 124 ] || [ "$uml_status" -eq 137 ]; then
    fail "UML did not finish within ${limit} s"
  fi
  fail "UML ended (status $uml_status) without a test result"
fi
status=$(cat "$work/result")
if [ "$status" != 0 ]; then
  echo "--- UML console ($work/console.log)"
  tail -n 80 "$work/console.log"
  fail "test exit status $status after ${elapsed} s (logs in $work)"
fi
# A filter that matched nothing passes in GoogleTest: one test must have run.
grep -q '^\[  PASSED  \] 1 test\.' "$work/test.log" || fail "not exactly one test ran for filter $filter"
echo "system test $filter passed in ${elapsed} s (UML)"
