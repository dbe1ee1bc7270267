#!/usr/bin/env bash
# Issues, with the identity CA of a site made by
# deploy/security/make-site-pki.sh, a key and a certificate with explicit
# validity dates: the tests' expired (or not yet valid) identities; with
# EXTENSIONS, certificates with those X.509v3 extensions instead of an
# identity's (a CA certificate: "basicConstraints=critical,CA:TRUE").
#   issue_test_cert.sh PKI_DIR ROLE NAME START END OUT_DIR [EXTENSIONS]
# START and END as openssl ca takes them: YYYYMMDDHHMMSSZ (UTC).
set -euo pipefail
[ $# -eq 6 ] || [ $# -eq 7 ] ||
  { echo "usage: issue_test_cert.sh PKI_DIR ROLE NAME START END OUT_DIR [EXTENSIONS]" >&2; exit 2; }
pki=$1 role=$2 name=$3 start=$4 end=$5 out=$6 extensions=${7:-}
site=$(sed -n 's/^site=//p' "$pki/site.conf")
mkdir -p "$out"
declare -a extfile=()
if [ -n "$extensions" ]; then
  echo "$extensions" >"$out/extensions.cnf"
  extfile=(-extfile "$out/extensions.cnf")
fi
openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:prime256v1 -out "$out/key.pem" 2>/dev/null
openssl req -new -key "$out/key.pem" -subj "/O=$site/OU=$role/CN=$name" -out "$out/request.csr"
openssl ca -batch -notext -config "$pki/ca/identity/openssl.cnf" -startdate "$start" -enddate "$end" \
  "${extfile[@]}" -in "$out/request.csr" -out "$out/cert.pem" 2>"$out/openssl-ca.log" ||
  { cat "$out/openssl-ca.log" >&2; exit 1; }
rm -f "$out/request.csr" "$out/openssl-ca.log" "$out/extensions.cnf"
