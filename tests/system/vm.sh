# What run_in_vm.sh needs to choose and boot a virtual machine with a kernel
# CAN stack; sourced (bash). Every probe's answer is kept in a directory
# beside the tests' work directories, for as long as this machine's boot
# lasts (keyed by its boot id and the installed packages), under a lock, so
# that a probe runs once per test run, not once per test.
#
#   choose_vm DIR       sets vm_kind (uml or qemu), vm_accel (qemu: kvm or
#                       tcg), vm_kernel (qemu: the kernel image) and
#                       vm_reason (why); returns 1 with vm_reason if neither
#                       can be used
#   can_modules KIND KERNEL
#                       prints the CAN modules' files in load order
#   boot_vm INIT CONSOLE LIMIT
#                       boots the chosen machine with INIT as its init;
#                       the exit status of timeout(1)

vm_dir=
vm_kind=
vm_accel=
vm_kernel=
vm_reason=

# UML's CAN modules, in load order.
uml_can_modules=(net/can/can.ko net/can/can-raw.ko drivers/net/can/dev/can-dev.ko
                 drivers/net/can/vcan.ko)

uml_binary() { command -v linux.uml || command -v linux; }

uml_modules_dir() { ls -d /usr/lib/uml/modules/*/kernel 2>/dev/null | sort -V | tail -n 1; }

# The newest installed kernel of Debian's linux-image packages that has the
# CAN modules.
qemu_kernel() {
  local image
  for image in /boot/vmlinuz-*; do
    [ -e "/lib/modules/${image#/boot/vmlinuz-}/kernel/net/can/can-raw.ko" ] && echo "$image"
  done | sort -V | tail -n 1 | grep .
}

# The files of MODULES (and what they depend on) for kernel VERSION, in the
# order insmod must load them, each once.
module_files() {
  local version=$1
  shift
  modprobe -a -S "$version" --show-depends "$@" | awk '$1 == "insmod" && !seen[$2]++ { print $2 }'
}

can_modules() {
  local kind=$1 kernel=$2 dir m
  if [ "$kind" = uml ]; then
    dir=$(uml_modules_dir)
    [ -n "$dir" ] || { vm_reason="the UML CAN modules are missing (/usr/lib/uml/modules): run bash .ci/deps"; return 1; }
    for m in "${uml_can_modules[@]}"; do echo "$dir/$m"; done
  else
    module_files "${kernel#/boot/vmlinuz-}" can can_raw can_dev vcan
  fi
}

# What the probes' answers depend on.
probe_key() {
  echo "boot $(cat /proc/sys/kernel/random/boot_id 2>/dev/null) kernel $(uname -r)" \
    "$(dpkg-query -W -f='${Package} ${Version} ' user-mode-linux qemu-system-x86 linux-image-amd64 2>/dev/null)"
}

# Boots UML with an init that only leaves a mark: whether it can run a
# process at all.
probe_uml() {
  local uml dir=$vm_dir/uml-probe
  uml=$(uml_binary) || { probe_note="User-Mode Linux is not installed (package user-mode-linux)"; return 1; }
  rm -rf "$dir" && mkdir -p "$dir"
  printf '#!/bin/sh\necho ran > %s/ran\nPATH=/usr/sbin:/usr/bin:/sbin:/bin halt -f\n' "$dir" > "$dir/init"
  chmod +x "$dir/init"
  local start=$SECONDS
  timeout --kill-after=5 30 "$uml" mem=128M rootfstype=hostfs rootflags=/ rw init="$dir/init" \
    con=null con0=fd:0,fd:1 </dev/null >"$dir/console.log" 2>&1
  if [ -f "$dir/ran" ]; then
    probe_note="User-Mode Linux ran its init ($((SECONDS - start)) s)"
    return 0
  fi
  local why
  why=$(grep -m1 -E 'Kernel panic|Segmentation|segfault|exitcode' "$dir/console.log" | tr -d '\r')
  probe_note="User-Mode Linux could not run its init: ${why:-no mark left (console in $dir/console.log)}"
  return 1
}

# The initramfs of the QEMU guest: busybox, the modules for virtio and 9p,
# and qemu_initramfs_init.sh as /init, which mounts this machine's root
# over 9p and hands over to the init named on the kernel command line.
# Built from the installed kernel's modules, once per kernel and probe key.
qemu_initramfs() {
  local kernel=$1 version out root m key
  version=${kernel#/boot/vmlinuz-}
  out=$vm_dir/initramfs-$version.cpio.gz
  key=$(probe_key)
  if [ ! -s "$out" ] || [ "$(cat "$out.key" 2>/dev/null)" != "$key" ]; then
    [ -x /bin/busybox ] || { vm_reason="busybox (package busybox-static) is not installed: run bash .ci/deps"; return 1; }
    command -v cpio >/dev/null || { vm_reason="cpio is not installed: run bash .ci/deps"; return 1; }
    root=$vm_dir/initramfs-$version
    rm -rf "$root" && mkdir -p "$root/bin" "$root/modules"
    cp /bin/busybox "$root/bin/busybox"
    cp "$(dirname "${BASH_SOURCE[0]}")/qemu_initramfs_init.sh" "$root/init"
    chmod +x "$root/init"
    : > "$root/modules/order"
    for m in $(module_files "$version" virtio_pci 9pnet_virtio 9p); do
      case "$m" in
        *.ko) cp "$m" "$root/modules/" ;;
        *.ko.xz) xz -dc "$m" > "$root/modules/$(basename "$m" .xz)" ;;
        *) vm_reason="cannot put $m into the initramfs (unknown compression)"; return 1 ;;
      esac
      basename "${m%.xz}" >> "$root/modules/order"
    done
    [ -s "$root/modules/order" ] || { vm_reason="no virtio/9p modules for kernel $version"; return 1; }
    (cd "$root" && find . | cpio -o -H newc --quiet | gzip -1) > "$out.tmp" && mv "$out.tmp" "$out"
    echo "$key" > "$out.key"
  fi
  echo "$out"
}

qemu_boot() {  # ACCEL KERNEL INIT CONSOLE LIMIT
  local accel=$1 kernel=$2 init=$3 console=$4 limit=$5 initramfs
  initramfs=$(qemu_initramfs "$kernel") || return 1
  timeout --kill-after=10 "$limit" qemu-system-x86_64 -accel "$accel" -smp 2 -m 1536 \
    -nodefaults -display none -serial stdio -no-reboot \
    -kernel "$kernel" -initrd "$initramfs" \
    -append "console=ttyS0 panic=-1 quiet dnbridge.init=$init" \
    -virtfs local,path=/,mount_tag=hostroot,security_model=passthrough,multidevs=remap,id=hostroot \
    </dev/null >"$console" 2>&1
}

# KVM only where a guest actually boots with it (nested KVM may hang in
# early boot): a guest whose init only leaves a mark, within 15 s.
probe_kvm() {
  local dir=$vm_dir/kvm-probe
  [ -w /dev/kvm ] || { probe_note="no usable /dev/kvm"; return 1; }
  rm -rf "$dir" && mkdir -p "$dir"
  printf '#!/bin/sh\necho ran > %s/ran\nPATH=/usr/sbin:/usr/bin:/sbin:/bin poweroff -f\n' "$dir" > "$dir/init"
  chmod +x "$dir/init"
  local start=$SECONDS
  qemu_boot kvm "$vm_kernel" "$dir/init" "$dir/console.log" 15
  if [ -f "$dir/ran" ]; then
    probe_note="KVM boots ($((SECONDS - start)) s)"
    return 0
  fi
  probe_note="KVM did not boot a guest within 15 s: TCG"
  return 1
}

choose_qemu() {
  command -v qemu-system-x86_64 >/dev/null ||
    { vm_reason="QEMU is not installed (package qemu-system-x86): run bash .ci/deps"; return 1; }
  vm_kernel=$(qemu_kernel) ||
    { vm_reason="no kernel with CAN modules in /boot (package linux-image-amd64): run bash .ci/deps"; return 1; }
  [ "$(id -u)" -eq 0 ] ||
    { vm_reason="QEMU's guest shares this machine's root over 9p as root: run as root"; return 1; }
  qemu_initramfs "$vm_kernel" >/dev/null || return 1
  local key accel note
  key="$(probe_key) $vm_kernel"
  if [ -f "$vm_dir/qemu-accel" ] && [ "$(sed -n 1p "$vm_dir/qemu-accel")" = "$key" ]; then
    accel=$(sed -n 2p "$vm_dir/qemu-accel")
    note="$(sed -n 3p "$vm_dir/qemu-accel") (probed earlier this boot)"
  else
    if probe_kvm; then accel=kvm; else accel=tcg; fi
    note=$probe_note
    printf '%s\n%s\n%s\n' "$key" "$accel" "$note" > "$vm_dir/qemu-accel"
  fi
  vm_kind=qemu
  vm_accel=$accel
  vm_reason="$vm_reason; $note; kernel $vm_kernel"
}

choose_vm() {
  vm_dir=$1
  mkdir -p "$vm_dir"
  local lock status=0
  exec {lock}>"$vm_dir/lock"
  flock "$lock"
  case "${DNBRIDGE_VM:-auto}" in
    uml)
      vm_kind=uml
      vm_reason="forced by DNBRIDGE_VM=uml"
      uml_binary >/dev/null || { vm_reason="User-Mode Linux is not installed (package user-mode-linux): run bash .ci/deps"; status=1; }
      ;;
    qemu)
      vm_reason="forced by DNBRIDGE_VM=qemu"
      choose_qemu || status=1
      ;;
    auto)
      local key
      key=$(probe_key)
      if [ -f "$vm_dir/uml" ] && [ "$(sed -n 1p "$vm_dir/uml")" = "$key" ]; then
        vm_kind=$(sed -n 2p "$vm_dir/uml")
        vm_reason="$(sed -n 3p "$vm_dir/uml") (probed earlier this boot)"
      else
        if probe_uml; then vm_kind=uml; else vm_kind=qemu; fi
        vm_reason=$probe_note
        printf '%s\n%s\n%s\n' "$key" "$vm_kind" "$probe_note" > "$vm_dir/uml"
      fi
      if [ "$vm_kind" = qemu ]; then choose_qemu || status=1; fi
      ;;
    *)
      vm_reason="DNBRIDGE_VM must be auto, uml or qemu, not '$DNBRIDGE_VM'"
      status=1
      ;;
  esac
  exec {lock}>&-
  return "$status"
}

boot_vm() {  # INIT CONSOLE LIMIT
  local init=$1 console=$2 limit=$3
  if [ "$vm_kind" = uml ]; then
    timeout --kill-after=10 "$limit" "$(uml_binary)" mem=512M rootfstype=hostfs rootflags=/ rw \
      init="$init" con=null con0=fd:0,fd:1 </dev/null >"$console" 2>&1
  else
    qemu_boot "$vm_accel" "$vm_kernel" "$init" "$console" "$limit"
  fi
}
