#!/usr/bin/env bash
# Installs the Debian package .ci/package built on this machine, checks what
# it installed, purges it and checks the machine is as it was. Needs root
# (or sudo without a password): dpkg -i and dpkg --purge. Fails, never
# skips: a missing .deb, file, user or tool is a failure.
#   install_test.sh PATH/dnbridge_VERSION_ARCH.deb
set -euo pipefail

deb=${1:?usage: install_test.sh PACKAGE.deb}
fail() { echo "FAIL: $*" >&2; exit 1; }
[ -f "$deb" ] || fail "$deb: no such package (bash .ci/package builds it)"
deb=$(realpath "$deb")
as_root=()
if [ "$(id -u)" -ne 0 ]; then
  sudo -n true 2>/dev/null || fail "needs root or passwordless sudo for dpkg -i"
  as_root=(sudo -n)
fi
for tool in dpkg dpkg-deb dpkg-query systemd-analyze runuser getent; do
  command -v "$tool" >/dev/null || fail "$tool not found"
done

installed() { dpkg-query -W -f='${Status}' dnbridge 2>/dev/null | grep -q "installed"; }
# Nothing of someone else's is touched: purge would take these away.
installed && fail "a dnbridge package is already installed; remove it first"
getent passwd dnbridge >/dev/null && fail "a user dnbridge already exists"
getent group dnbridge >/dev/null && fail "a group dnbridge already exists"
[ -e /etc/dnbridge ] && fail "/etc/dnbridge already exists"
accounts_before=$(getent passwd; getent group)

# Every file (not directory) in the package, as installed.
mapfile -t paths < <(dpkg-deb -c "$deb" | awk '$1 !~ /^d/ {print $6}' | sed 's|^\./|/|')
[ "${#paths[@]}" -ge 10 ] || fail "$deb lists only ${#paths[@]} files"
version=$(dpkg-deb -f "$deb" Version)

purged=0
cleanup() { [ "$purged" = 1 ] || "${as_root[@]}" dpkg --purge dnbridge >/dev/null 2>&1 || true; }
trap cleanup EXIT

echo "== dpkg -i $(basename "$deb")"
"${as_root[@]}" dpkg -i "$deb"
installed || fail "dpkg reports dnbridge not installed"

echo "== files"
unit_dir=""
for f in /usr/bin/dnbridge /usr/bin/dnbctl /usr/bin/cdn127-sim \
         /usr/share/dnbridge/idl/dnbridge.idl /usr/share/dnbridge/cyclonedds/loopback.xml \
         /etc/dnbridge/rack-example.toml /etc/dnbridge/cyclonedds.xml \
         /usr/lib/sysusers.d/dnbridge.conf /usr/share/dnbridge/security/make-site-pki.sh \
         /usr/share/doc/dnbridge/security.md /usr/share/doc/dnbridge/operations.md \
         /usr/share/dnbridge/networkd/80-dnbridge-can0.network \
         /usr/share/dnbridge/networkd/80-dnbridge-can1.network \
         /usr/share/dnbridge/networkd/70-dnbridge-can.link \
         /usr/share/dnbridge/cdn127-sim-example.toml; do
  [ -f "$f" ] || fail "$f not installed"
done
for d in /lib/systemd/system /usr/lib/systemd/system; do
  [ -f "$d/dnbridge@.service" ] && unit_dir=$d && break
done
[ -n "$unit_dir" ] || fail "dnbridge@.service not installed"
for f in /usr/bin/dnbridge /usr/bin/dnbctl /usr/bin/cdn127-sim /usr/share/dnbridge/security/make-site-pki.sh; do
  [ -x "$f" ] || fail "$f not executable"
done
conffiles=$(dpkg-query -W -f='${Conffiles}' dnbridge)
for f in /etc/dnbridge/rack-example.toml /etc/dnbridge/cyclonedds.xml; do
  grep -q "$f" <<<"$conffiles" || fail "$f is not a conffile"
done

echo "== the dnbridge user"
getent passwd dnbridge >/dev/null || fail "postinst made no user dnbridge"
getent group dnbridge >/dev/null || fail "postinst made no group dnbridge"
[ "$(getent passwd dnbridge | cut -d: -f7)" = /usr/sbin/nologin ] || fail "user dnbridge can log in"
[ "$(id -u dnbridge)" -lt 1000 ] || fail "user dnbridge is not a system user"

echo "== systemd-analyze verify dnbridge@rack-example.service"
# Loads the template as the instance of the shipped configuration and checks
# its directives and that ExecStart's binary exists.
out=$(systemd-analyze verify "$unit_dir/dnbridge@rack-example.service" 2>&1) ||
  fail "systemd-analyze verify: $out"
[ -z "$out" ] || echo "$out"
if grep -i "dnbridge" <<<"$out"; then fail "systemd-analyze verify warns about the unit"; fi
unit=$unit_dir/dnbridge@.service
for directive in Type=notify WatchdogSec= Restart=on-failure User=dnbridge NoNewPrivileges=yes \
                 ProtectSystem=strict ProtectHome=yes \
                 "RestrictAddressFamilies=AF_CAN AF_INET AF_INET6 AF_UNIX AF_NETLINK" \
                 "ExecStart=/usr/bin/dnbridge --config /etc/dnbridge/%i.toml" \
                 "Environment=CYCLONEDDS_URI=file:///etc/dnbridge/cyclonedds.xml"; do
  grep -q "^$directive" "$unit" || fail "$unit has no $directive"
done

echo "== the programs"
# As the service's user: the configuration must be readable by it.
runuser -u dnbridge -- /usr/bin/dnbridge --check-config /etc/dnbridge/rack-example.toml ||
  fail "dnbridge --check-config refuses the shipped configuration"
got=$(/usr/bin/dnbridge --version)
[ "$got" = "dnbridge $version" ] || fail "dnbridge --version says '$got', the package is $version"
/usr/bin/dnbctl --help >/dev/null || fail "dnbctl --help"
/usr/bin/cdn127-sim --help >/dev/null || fail "cdn127-sim --help"

echo "== dpkg --purge dnbridge"
"${as_root[@]}" dpkg --purge dnbridge
purged=1
installed && fail "dnbridge still installed after purge"
for p in "${paths[@]}"; do
  if [ -e "$p" ] || [ -L "$p" ]; then fail "$p left after purge"; fi
done
for d in /etc/dnbridge /usr/share/dnbridge /usr/share/doc/dnbridge /var/log/dnbridge; do
  [ -e "$d" ] && fail "$d left after purge"
done
getent passwd dnbridge >/dev/null && fail "user dnbridge left after purge"
getent group dnbridge >/dev/null && fail "group dnbridge left after purge"
[ "$(getent passwd; getent group)" = "$accounts_before" ] || fail "accounts differ from before"
echo "package installed, checked and purged: OK"
