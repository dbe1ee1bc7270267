#!/usr/bin/env bash
# deploy/security/make-site-pki.sh as an administrator uses it, in a
# temporary directory: refused first runs (nothing left behind), first run,
# run again (nothing reissued), a role change and a site change refused, a
# host added, a host renewed, new CAs with a new site name; after each, the
# certificates verify against the identity CA and the documents against the
# permissions CA as openssl sees them. Fails, never skips.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
script=$here/../../deploy/security/make-site-pki.sh
fail() { echo "FAIL: $*" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pki=$work/pki
run() { bash "$script" --out "$pki" "$@" >"$work/out" 2>&1; }
fingerprint() { openssl x509 -in "$1" -noout -fingerprint -sha256; }
# Every host's certificate verifies against the identity CA, both signed
# documents against the permissions CA.
verify_all() {
  for host in "$pki"/hosts/*/; do
    openssl verify -CAfile "$pki/ca/identity/ca.pem" "$host/cert.pem" >/dev/null ||
      fail "$host/cert.pem does not verify against the identity CA"
    for doc in governance permissions; do
      cmp -s "$pki/$doc.p7s" "$host/$doc.p7s" || fail "$host/$doc.p7s is not the site's"
    done
    cmp -s "$pki/ca/identity/ca.pem" "$host/identity_ca.pem" || fail "$host/identity_ca.pem is not the site's"
    [ "$(stat -c %a "$host/key.pem")" = 600 ] || fail "$host/key.pem is readable by others"
  done
  for doc in governance permissions; do
    openssl smime -verify -text -in "$pki/$doc.p7s" -CAfile "$pki/ca/permissions/ca.pem" \
      >"$work/$doc.out" 2>/dev/null || fail "$doc.p7s does not verify against the permissions CA"
    # S/MIME signs the text with CRLF line ends.
    tr -d '\r' <"$work/$doc.out" | cmp -s - "$pki/$doc.xml" || fail "$doc.p7s does not sign $doc.xml"
  done
  [ "$(stat -c %a "$pki/ca/identity/ca.key")" = 600 ] || fail "the identity CA key is readable by others"
}

echo "== the first run needs a domain; a refused first run leaves nothing behind"
if run --bridge rack-A; then fail "ran without --domain"; fi
grep -q -- "--domain ID is required" "$work/out" || fail "no clear message: $(cat "$work/out")"
[ ! -e "$pki" ] || fail "a first run refused for its domain left $pki behind: $(ls -A "$pki")"
if run --domain 17 --bridge twice --monitor twice; then fail "one name got two roles"; fi
grep -q "twice is already a bridge" "$work/out" || fail "no clear message: $(cat "$work/out")"
[ ! -e "$pki" ] || fail "a first run refused for a role left $pki behind: $(ls -A "$pki")"

echo "== a site"
run --domain 17 --site acme --bridge rack-A --supervisor scada-1 --monitor ops-1 --days 30 ||
  fail "first run: $(cat "$work/out")"
verify_all
id_ca=$(fingerprint "$pki/ca/identity/ca.pem")
rack_a=$(fingerprint "$pki/hosts/rack-A/cert.pem")
grep -q "<id>17</id>" "$pki/governance.xml" || fail "governance is not for domain 17"
grep -q "<allow_unauthenticated_participants>false<" "$pki/governance.xml" || fail "unauthenticated participants allowed"
grep -q "<enable_join_access_control>true<" "$pki/governance.xml" || fail "join access control off"
[ "$(grep -c "<default>DENY</default>" "$pki/permissions.xml")" = 3 ] || fail "not every grant defaults to DENY"
subject=$(openssl x509 -in "$pki/hosts/ops-1/cert.pem" -noout -subject -nameopt RFC2253 | sed 's/^subject=//')
grep -q "<subject_name>$subject</subject_name>" "$pki/permissions.xml" || fail "no grant names $subject"
# The monitor's grant: PumpState, DeviceState, NodeStatus, PortStatus read; nothing written.
grant=$(sed -n '/<grant name="monitor-ops-1">/,/<\/grant>/p' "$pki/permissions.xml")
grep -q "<publish>" <<<"$grant" && fail "the monitor may publish"
[ "$(grep -c "<topic>" <<<"$grant")" = 4 ] || fail "the monitor reads other than the four state topics"
days=$(( ( $(date -d "$(openssl x509 -in "$pki/hosts/rack-A/cert.pem" -noout -enddate | cut -d= -f2)" +%s) - $(date +%s) ) / 86400 ))
[ "$days" -ge 29 ] && [ "$days" -le 30 ] || fail "--days 30 gave a certificate valid $days days"

echo "== the same command again: nothing reissued"
run --domain 17 --site acme --bridge rack-A --supervisor scada-1 --monitor ops-1 || fail "second run: $(cat "$work/out")"
[ "$(fingerprint "$pki/ca/identity/ca.pem")" = "$id_ca" ] || fail "the identity CA changed"
[ "$(fingerprint "$pki/hosts/rack-A/cert.pem")" = "$rack_a" ] || fail "rack-A was reissued"
verify_all

echo "== a name keeps its role"
cp "$pki/roster" "$work/roster.before"
if run --bridge rack-B --monitor scada-1; then fail "scada-1 became a monitor"; fi
grep -q "scada-1 is already a supervisor" "$work/out" || fail "no clear message: $(cat "$work/out")"
cmp -s "$pki/roster" "$work/roster.before" || fail "a refused run changed the roster"
[ ! -e "$pki/hosts/rack-B" ] || fail "a refused run issued rack-B"

echo "== the site name is kept"
if run --site other-name --bridge rack-B; then fail "the site name changed without new CAs"; fi
grep -q "belongs to site 'acme', not 'other-name' (.*it changes only with --new-ca)" "$work/out" ||
  fail "no clear message: $(cat "$work/out")"
cmp -s "$pki/roster" "$work/roster.before" || fail "a refused site change changed the roster"
grep -q "^site=acme$" "$pki/site.conf" || fail "a refused site change changed site.conf"

echo "== a host added, the site's domain kept"
run --bridge rack-B || fail "adding rack-B: $(cat "$work/out")"
[ "$(fingerprint "$pki/hosts/rack-A/cert.pem")" = "$rack_a" ] || fail "adding rack-B reissued rack-A"
grep -q "<subject_name>CN=rack-B,OU=bridge,O=acme</subject_name>" "$pki/permissions.xml" || fail "no grant for rack-B"
grep -q "<id>17</id>" "$pki/permissions.xml" || fail "the domain was not kept"
verify_all

echo "== rack scopes"
# grant ROLE-NAME: that identity's grant.
grant_of() { sed -n "/<grant name=\"$1\">/,/<\/grant>/p" "$pki/permissions.xml"; }
for bad in "--monitor ops-2=rack-A" "--bridge rack-C=rack-C,rack-D" "--supervisor s=rack:A" \
  "--supervisor s=" "--supervisor s=rack-A,,rack-B" "--supervisor s=rack-A,"; do
  # shellcheck disable=SC2086 # the words of each case
  roster_before=$(cat "$pki/roster")
  if run $bad; then fail "ran with $bad"; fi
  grep -q "make-site-pki: --" "$work/out" || fail "no clear message for $bad: $(cat "$work/out")"
  [ "$(cat "$pki/roster")" = "$roster_before" ] || fail "a refused $bad changed the roster"
  [ ! -e "$pki/hosts/s" ] && [ ! -e "$pki/hosts/ops-2" ] && [ ! -e "$pki/hosts/rack-C" ] ||
    fail "a refused $bad issued an identity"
done
run --bridge rack-A=rack-A --supervisor scada-2=rack-A,rack-B || fail "scopes: $(cat "$work/out")"
[ "$(fingerprint "$pki/hosts/rack-A/cert.pem")" = "$rack_a" ] || fail "scoping rack-A reissued it"
grep -q "^bridge rack-A rack-A$" "$pki/roster" || fail "the roster lacks rack-A's rack: $(cat "$pki/roster")"
grant=$(grant_of supervisor-scada-2)
grep -q "<partition>dnbridge/rack-A</partition>" <<<"$grant" || fail "scada-2 lacks rack-A's partition"
grep -q "<partition>dnbridge/rack-B</partition>" <<<"$grant" || fail "scada-2 lacks rack-B's partition"
if grep -q "dnbridge/\*\|<partition></partition>" <<<"$grant"; then fail "scada-2 has every rack or the default partition"; fi
grep -q "racks: rack-A,rack-B" "$pki/hosts/scada-2/security.toml" || fail "scada-2's security.toml does not say its racks"
grant=$(grant_of bridge-rack-A)
grep -q "<partition>dnbridge/rack-A</partition>" <<<"$grant" || fail "rack-A lacks its partition"
if grep -q "dnbridge/\*" <<<"$grant"; then fail "rack-A still has every rack"; fi
# The state topics stay in the default partition (a rule without partitions).
grep -q "<topic>dnbridge/PumpState</topic>" <<<"$grant" || fail "rack-A may not publish PumpState"
# Given again without racks, a name keeps them; "=*" gives every rack back.
run --supervisor scada-2 || fail "scada-2 again: $(cat "$work/out")"
grep -q "^supervisor scada-2 rack-A,rack-B$" "$pki/roster" || fail "scada-2 lost its racks: $(cat "$pki/roster")"
run --supervisor 'scada-2=*' || fail "scada-2=*: $(cat "$work/out")"
grep -q "^supervisor scada-2$" "$pki/roster" || fail "scada-2=* kept racks: $(cat "$pki/roster")"
grep_grant=$(grant_of supervisor-scada-2)
grep -q "<partition>dnbridge/\*</partition>" <<<"$grep_grant" || fail "scada-2=* has not every rack"
# The default partition for the topics of versions before partitions, not
# for DeviceCommand (newer): the rule that names it has every rack's only.
grep -q "<partition></partition>" <<<"$grep_grant" || fail "scada-2=* lacks the default partition"
device_rule=$(awk '/<publish>/ { r = "" } { r = r $0 "\n" } /<\/publish>/ && r ~ /DeviceCommand/ { printf "%s", r }' <<<"$grep_grant")
[ -n "$device_rule" ] || fail "scada-2=* may not publish DeviceCommand"
if grep -q "<partition></partition>\|PumpCommand" <<<"$device_rule"; then
  fail "DeviceCommand is granted in the default partition: $device_rule"
fi
verify_all

echo "== a host renewed"
run --renew rack-A || fail "renewing rack-A: $(cat "$work/out")"
[ "$(fingerprint "$pki/hosts/rack-A/cert.pem")" != "$rack_a" ] || fail "--renew kept the certificate"
[ "$(fingerprint "$pki/ca/identity/ca.pem")" = "$id_ca" ] || fail "--renew changed the CA"
verify_all

echo "== new CAs"
if run --new-ca --monitor scada-1; then fail "--new-ca with a role change ran"; fi
if ls -d "$pki"/previous-* >/dev/null 2>&1; then fail "a refused --new-ca moved the PKI aside"; fi
[ "$(fingerprint "$pki/ca/identity/ca.pem")" = "$id_ca" ] || fail "a refused --new-ca changed the CA"
run --new-ca --site acme-2 || fail "--new-ca: $(cat "$work/out")"
[ "$(fingerprint "$pki/ca/identity/ca.pem")" != "$id_ca" ] || fail "--new-ca kept the identity CA"
ls -d "$pki"/previous-*/ca/identity >/dev/null || fail "the old CAs were not kept aside"
[ "$(ls "$pki/hosts" | wc -l)" = 5 ] || fail "not every identity was issued again: $(ls "$pki/hosts")"
verify_all
# The new site name, everywhere.
grep -q "^site=acme-2$" "$pki/site.conf" || fail "site.conf kept the old site name"
for cert in "$pki"/ca/*/ca.pem "$pki"/hosts/*/cert.pem; do
  openssl x509 -in "$cert" -noout -subject -nameopt RFC2253 | grep -q ",O=acme-2$" ||
    fail "$cert is not of site acme-2: $(openssl x509 -in "$cert" -noout -subject)"
done
grep -q "<subject_name>CN=rack-A,OU=bridge,O=acme-2</subject_name>" "$pki/permissions.xml" ||
  fail "the grants do not name the new subjects"
if grep -q "O=acme<" "$pki/permissions.xml"; then fail "a grant names an old subject"; fi
echo "OK"
