#!/bin/busybox sh
# /init of the QEMU guest's initramfs (vm.sh builds it: busybox and the
# virtio and 9p modules): loads the modules, mounts this machine's root
# filesystem (QEMU's virtfs "hostroot") and hands over to the init that
# run_in_vm.sh named on the kernel command line (dnbridge.init=PATH).
# PID 1: on any failure it says why and powers the guest off.
/bin/busybox --install -s /bin
export PATH=/bin

die() {
  echo "initramfs: $*"
  poweroff -f
  sleep 60
}

mkdir -p /proc /newroot
mount -t proc proc /proc || die "cannot mount /proc"
for m in $(cat /modules/order); do
  insmod "/modules/$m" || die "insmod $m failed"
done
target=
for word in $(cat /proc/cmdline); do
  case "$word" in dnbridge.init=*) target=${word#dnbridge.init=} ;; esac
done
[ -n "$target" ] || die "no dnbridge.init= on the kernel command line"
mount -t 9p -o trans=virtio,version=9p2000.L,msize=512000,access=any hostroot /newroot ||
  die "cannot mount the host's root over 9p"
[ -x "/newroot$target" ] || die "$target is not there over 9p"
umount /proc
exec switch_root /newroot "$target"
