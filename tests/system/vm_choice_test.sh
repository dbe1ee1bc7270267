#!/usr/bin/env bash
# How run_in_vm.sh chooses its machine (vm.sh), without booting a test:
# a User-Mode Linux that dies before its init runs (a stand-in `linux` that
# fails as UML 6.1 does on CPUs with AMX) makes the probe take QEMU and say
# why; the answer is kept for the next test of the run; DNBRIDGE_VM forces a
# machine and refuses what it does not know.
#   vm_choice_test.sh WORK_DIR
set -uo pipefail
# The automatic choice is under test: whatever the caller forced does not apply.
unset DNBRIDGE_VM
here=$(cd "$(dirname "$0")" && pwd)
work=$1
rm -rf "$work/fake-uml" "$work/probe/uml"
mkdir -p "$work/fake-uml" "$work/probe"

failures=0
check() {  # DESCRIPTION CONDITION...
  local what=$1
  shift
  if "$@"; then echo "ok: $what"; else echo "FAILED: $what"; failures=$((failures + 1)); fi
}
contains() { [[ $1 == *"$2"* ]]; }

cat > "$work/fake-uml/linux" <<'FAKE'
#!/bin/sh
echo "Kernel panic - not syncing: Attempted to kill init! exitcode=0x0000000b"
exit 1
FAKE
chmod +x "$work/fake-uml/linux"
ln -s linux "$work/fake-uml/linux.uml"

# shellcheck source=tests/system/vm.sh
source "$here/vm.sh"
PATH=$work/fake-uml:$PATH choose_vm "$work/probe"
echo "chose: $vm_kind ${vm_accel:-} ($vm_reason)"
check "a UML that cannot run its init falls back to QEMU" [ "$vm_kind" = qemu ]
check "the reason names what UML printed" contains "$vm_reason" "could not run its init: Kernel panic"
check "QEMU runs on an accelerator that was probed" contains " kvm tcg " " $vm_accel "
check "QEMU boots Debian's kernel" contains "$vm_reason" "kernel /boot/vmlinuz-"

PATH=$work/fake-uml:$PATH choose_vm "$work/probe"
check "the next test of the run takes the kept answer" contains "$vm_reason" "could not run its init: Kernel panic - not syncing"
check "and says it was probed earlier" contains "$vm_reason" "(probed earlier this boot)"

DNBRIDGE_VM=qemu PATH=$work/fake-uml:$PATH choose_vm "$work/probe"
check "DNBRIDGE_VM=qemu forces QEMU" [ "$vm_kind" = qemu ]
check "and says so" contains "$vm_reason" "forced by DNBRIDGE_VM=qemu"

if DNBRIDGE_VM=bochs choose_vm "$work/probe"; then status=0; else status=1; fi
check "an unknown DNBRIDGE_VM is refused" [ "$status" = 1 ]
check "with what it may be" contains "$vm_reason" "DNBRIDGE_VM must be auto, uml or qemu"

if ((failures)); then
  echo "$failures check(s) failed"
  exit 1
fi
echo "every check passed"
