#!/usr/bin/env bash
# The PKI the security tests use, made at test time (ctest fixture
# security_pki) with the shipped deploy/security/make-site-pki.sh:
#   OUT/site      site "test-site": bridge "rack", supervisor "scada",
#                 monitor "ops"
#   OUT/other     site "other-site", CAs of its own: bridge "rack"
#   OUT/expired   bridge "rack" of test-site, certified by its identity CA
#                 for 2020 only (openssl ca -startdate/-enddate)
#   OUT/rack-before-late   the bridge's files as they were before monitor
#                 "late" was added to test-site (a second run of the script)
#   OUT/rack-before-services   the bridge's files with permissions as a
#                 site signed them before the bus scan and reload came (no
#                 BusScan*/Reload* grant), signed by test-site's permissions CA
#   OUT/sub-ca    a CA certificate (CA:TRUE) and its key, issued by
#                 test-site's identity CA, valid now
#   OUT/bad-date/not_before.pem, not_after.pem   test-site's identity CA
#                 with the last digit of that date made an "X": OpenSSL
#                 reads the certificate but cannot compare the date
#   make_test_pki.sh OUT DOMAIN
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: make_test_pki.sh OUT DOMAIN" >&2; exit 2; }
out=$1 domain=$2
here=$(cd "$(dirname "$0")" && pwd)
script=$here/../../deploy/security/make-site-pki.sh
rm -rf "$out"
mkdir -p "$out"
bash "$script" --out "$out/site" --domain "$domain" --site test-site \
  --bridge rack --supervisor scada --monitor ops
cp -r "$out/site/hosts/rack" "$out/rack-before-late"
bash "$script" --out "$out/site" --monitor late
bash "$script" --out "$out/other" --domain "$domain" --site other-site --bridge rack
mkdir -p "$out/rack-before-services"
cp -r "$out/site/hosts/rack/." "$out/rack-before-services/"
sed -E '/dnbridge\/(BusScan|Reload)(Request|Reply)/d' "$out/site/permissions.xml" \
  >"$out/rack-before-services/permissions.xml"
openssl smime -sign -text -in "$out/rack-before-services/permissions.xml" \
  -out "$out/rack-before-services/permissions.p7s" \
  -signer "$out/site/ca/permissions/ca.pem" -inkey "$out/site/ca/permissions/ca.key"
bash "$here/issue_test_cert.sh" "$out/site" bridge rack 20200101000000Z 20210101000000Z "$out/expired"
now=$(date -u +%Y%m%d%H%M%SZ)
bash "$here/issue_test_cert.sh" "$out/site" bridge sub-ca "$now" "$(date -u -d '+30 days' +%Y%m%d%H%M%SZ)" \
  "$out/sub-ca" "basicConstraints=critical,CA:TRUE"

# spoil_date N FILE: the identity CA, its Nth time (1 notBefore, 2 notAfter)
# spoiled, to FILE. asn1parse gives each time's offset, header and length
# ("   78:d=3  hl=2 l=  13 prim: UTCTIME :261222095921Z").
spoil_date() {
  local der=$out/bad-date/ca.der at
  openssl x509 -in "$out/site/ca/identity/ca.pem" -outform DER -out "$der"
  at=$(openssl asn1parse -inform DER -in "$der" |
    sed -nE 's/^ *([0-9]+):d=[0-9]+ +hl=([0-9]+) +l= *([0-9]+) +prim: +(UTC|GENERALIZED)TIME.*/\1 \2 \3/p' |
    sed -n "${1}p")
  read -r offset header length <<<"$at"
  printf X | dd of="$der" bs=1 seek=$((offset + header + length - 2)) conv=notrunc status=none
  openssl x509 -inform DER -in "$der" -out "$2"
  rm "$der"
}
mkdir -p "$out/bad-date"
spoil_date 1 "$out/bad-date/not_before.pem"
spoil_date 2 "$out/bad-date/not_after.pem"
