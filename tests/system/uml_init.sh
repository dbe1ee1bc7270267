#!/bin/sh
# The init process of a User-Mode Linux kernel booted by run_in_uml.sh, with
# this machine's filesystem as its root (hostfs): mounts /proc and /sys,
# brings up lo, loads the CAN modules, creates vcan0 and vcan1, runs one
# system test and writes its exit status to WORK/result, then halts.
#   uml_init.sh WORK TEST_BINARY GTEST_FILTER CYCLONEDDS_XML
# It is PID 1: it must never exit before halt (the kernel would panic).
work=$1
binary=$2
filter=$3
dds_xml=$4
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
export HOME=/root

log() { echo "uml-init: $*"; }
finish() {
  echo "$1" > "$work/result"
  sync
  halt -f
  sleep 60
}

mount -t proc proc /proc
mount -t sysfs sysfs /sys
ip link set lo up

modules=/usr/lib/uml/modules/$(uname -r)/kernel
for m in net/can/can.ko net/can/can-raw.ko drivers/net/can/dev/can-dev.ko drivers/net/can/vcan.ko; do
  if ! insmod "$modules/$m"; then
    log "insmod $modules/$m failed"
    finish 90
  fi
done
for i in vcan0 vcan1; do
  if ! { ip link add dev "$i" type vcan && ip link set up "$i"; }; then
    log "cannot create $i"
    finish 91
  fi
done

# Only lo exists here: DDS on lo, unicast discovery to 127.0.0.1.
export CYCLONEDDS_URI="file://$dds_xml"
export DNBRIDGE_SYSTEM_WORK="$work"
log "running $binary --gtest_filter=$filter"
"$binary" --gtest_filter="$filter" --gtest_color=no > "$work/test.log" 2>&1
status=$?
log "test exit status $status"
finish "$status"
