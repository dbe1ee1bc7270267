#!/bin/sh
# The init process of the kernel run_in_vm.sh boots (User-Mode Linux or
# QEMU), with this machine's filesystem as its root: mounts /proc and /sys
# (and, in QEMU, the guest's own /dev), brings up lo, loads the CAN modules,
# creates vcan0 and vcan1, measures the guest's speed against this machine's
# (cpu_loop.sh), runs one system test and writes its exit status to
# WORK/result, then stops the machine.
#   guest_init.sh WORK      (WORK/guest.env and WORK/modules: run_in_vm.sh)
# It is PID 1: it must never exit before the machine stops (the kernel would
# panic).
work=$1
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
export HOME=/root
. "$work/guest.env"
here=$(dirname "$0")

log() { echo "guest-init: $*"; }
finish() {
  echo "$1" > "$work/result"
  sync
  if [ "$vm_kind" = uml ]; then halt -f; else poweroff -f; fi
  sleep 60
}

mount -t proc proc /proc
mount -t sysfs sysfs /sys
# Over 9p, /dev is this machine's directory: the guest needs its own.
[ "$vm_kind" = qemu ] && mount -t devtmpfs devtmpfs /dev
ip link set lo up

while read -r m; do
  if ! insmod "$m"; then
    log "insmod $m failed"
    finish 90
  fi
done < "$work/modules"
for i in vcan0 vcan1; do
  if ! { ip link add dev "$i" type vcan && ip link set up "$i"; }; then
    log "cannot create $i"
    finish 91
  fi
done

# The guest's speed factor (at least 1): the test's own patience scales by
# it, never a bound the product must meet.
guest_loop_ms=$(bash "$here/cpu_loop.sh")
tenths=$(( (guest_loop_ms * 10 + host_loop_ms - 1) / host_loop_ms ))
[ "$tenths" -ge 10 ] || tenths=10
export DNBRIDGE_SYSTEM_SLOWDOWN="$((tenths / 10)).$((tenths % 10))"
echo "factor $DNBRIDGE_SYSTEM_SLOWDOWN (reference loop: ${guest_loop_ms} ms in the guest," \
  "${host_loop_ms} ms on this machine)" > "$work/speed"

# Only lo exists here: DDS on lo, unicast discovery to 127.0.0.1.
export CYCLONEDDS_URI="file://$dds_xml"
export DNBRIDGE_SYSTEM_WORK="$work"
log "running $test_binary --gtest_filter=$gtest_filter (speed factor $DNBRIDGE_SYSTEM_SLOWDOWN)"
"$test_binary" --gtest_filter="$gtest_filter" --gtest_color=no > "$work/test.log" 2>&1
status=$?
log "test exit status $status"
finish "$status"
