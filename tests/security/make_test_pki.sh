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
bash "$here/issue_test_cert.sh" "$out/site" bridge rack 20200101000000Z 20210101000000Z "$out/expired"
