#!/usr/bin/env bash
# The DDS Security PKI of one dnbridge site, made with openssl: an identity
# CA, a permissions CA, an identity (key + certificate) per bridge,
# supervisory host and monitoring host, and the governance and permissions
# documents, signed S/MIME by the permissions CA. deploy/security/README.md
# says which files go to which host.
#
# Safe to run again: existing CAs and identities are kept (never
# overwritten unless --new-ca or --renew says so); names given again are
# skipped, new names are issued; the documents are rewritten for every
# identity of the site and signed again each run.
set -euo pipefail

usage() {
  cat <<'EOF'
usage: make-site-pki.sh --out DIR [--domain ID] [options] [--bridge NAME[=RACK]]...
                        [--supervisor NAME[=RACK,...]]... [--monitor NAME]...

Makes (or extends) the DDS Security PKI of a dnbridge site in DIR.

  --out DIR           where the PKI lives (created if absent)
  --domain ID         the DDS domain, 0..232 (required on the first run; later
                      runs keep the site's unless given)
  --site NAME         organisation in every subject (default: dnbridge-site;
                      later runs keep the site's, which changes only with
                      --new-ca)
  --bridge NAME[=RACK]
                      a rack's bridge: publishes PumpState, DeviceState,
                      NodeStatus, PortStatus, ExplicitReply, BusScanReply and
                      ReloadReply, reads PumpCommand, DeviceCommand,
                      ExplicitRequest, BusScanRequest and ReloadRequest;
                      with =RACK, the commands and requests of that rack
                      only
  --supervisor NAME[=RACK,...]
                      a supervisory host: reads every dnbridge topic, writes
                      PumpCommand, DeviceCommand, ExplicitRequest,
                      BusScanRequest and ReloadRequest; with =RACK,...,
                      commands and requests to those racks only (=* :
                      every rack again)
  --monitor NAME      a monitoring host: reads PumpState, DeviceState,
                      NodeStatus and PortStatus only
  --days N            validity of new identities and of the permissions
                      grants, days (default 365)
  --ca-days N         validity of new CAs, days (default 3650)
  --renew NAME        issue NAME a new key and certificate (it keeps its role)
  --new-ca            make new CAs even though DIR has them; the old PKI is
                      moved to DIR/previous-TIMESTAMP and every identity of
                      the site is issued again under the new CAs
  -h, --help          this text

Without =RACK a bridge or supervisor is granted every rack's partition
("dnbridge/*") and the default partition, where versions before partitions
exchange commands (DeviceCommand, newer, in "dnbridge/*" only); with it, the partitions "dnbridge/RACK" of those racks
only. Given again, a name keeps its racks unless new ones are given.

Names and racks: letters, digits, '.', '_' and '-'. Everything else is denied: a
participant can do only what its grant allows (default DENY), and a host
without an identity of the site cannot join the domain.

Per host, DIR/hosts/NAME/ holds what that host needs and nothing more:
identity_ca.pem, cert.pem, key.pem, permissions_ca.pem, governance.p7s,
permissions.p7s and security.toml (the [security] table for dnbridge or
dnbctl --security, its paths relative to itself).
EOF
}

fail() { echo "make-site-pki: $*" >&2; exit 1; }

out=""
domain=""
site=""
days=365
ca_days=3650
new_ca=0
declare -a add_roles=() add_names=() add_racks=() renew=()

need_value() { [ $# -ge 2 ] && [ -n "$2" ] || fail "$1 needs a value (--help)"; }
while [ $# -gt 0 ]; do
  case "$1" in
    --out) need_value "$@"; out=$2; shift 2 ;;
    --domain) need_value "$@"; domain=$2; shift 2 ;;
    --site) need_value "$@"; site=$2; shift 2 ;;
    --bridge | --supervisor | --monitor)
      need_value "$@"; add_roles+=("${1#--}"); add_names+=("${2%%=*}")
      if [[ $2 == *=* ]]; then add_racks+=("=${2#*=}"); else add_racks+=(""); fi
      shift 2 ;;
    --days) need_value "$@"; days=$2; shift 2 ;;
    --ca-days) need_value "$@"; ca_days=$2; shift 2 ;;
    --renew) need_value "$@"; renew+=("$2"); shift 2 ;;
    --new-ca) new_ca=1; shift ;;
    -h | --help) usage; exit 0 ;;
    *) fail "unknown argument '$1' (--help)" ;;
  esac
done

command -v openssl >/dev/null || fail "openssl not found (Debian package openssl)"
[ -n "$out" ] || fail "--out DIR is required (--help)"
is_count() { [[ $1 =~ ^[1-9][0-9]{0,5}$ ]]; }
is_count "$days" || fail "--days $days: a whole number of days, 1 or more"
is_count "$ca_days" || fail "--ca-days $ca_days: a whole number of days, 1 or more"
valid_name() { [[ $1 =~ ^[A-Za-z0-9._-]{1,64}$ ]]; }
for n in "${add_names[@]}" "${renew[@]}"; do
  valid_name "$n" || fail "'$n' is not a name: letters, digits, '.', '_', '-' (at most 64)"
done
# A rack scope, "=RACK,...": "*" (every rack) or rack names; a bridge has one.
for i in "${!add_names[@]}"; do
  scope=${add_racks[$i]}
  [ -n "$scope" ] || continue
  scope=${scope#=}
  case ${add_roles[$i]} in
    monitor) fail "--monitor ${add_names[$i]}=$scope: a monitor reads the state of every rack (no =RACK)" ;;
    bridge) [[ $scope != *,* ]] || fail "--bridge ${add_names[$i]}=$scope: a bridge serves one rack" ;;
  esac
  [ "$scope" = "*" ] && continue
  [[ $scope != ,* && $scope != *, ]] || fail "--${add_roles[$i]} ${add_names[$i]}=$scope: an empty rack name"
  IFS=, read -r -a racks_given <<<"$scope"
  [ "${#racks_given[@]}" -gt 0 ] || fail "--${add_roles[$i]} ${add_names[$i]}=: no rack named"
  for r in "${racks_given[@]}"; do
    valid_name "$r" || fail "--${add_roles[$i]} ${add_names[$i]}=$scope: '$r' is not a rack name this script grants: letters, digits, '.', '_', '-' (at most 64)"
  done
done
if [ -n "$site" ]; then
  valid_name "$site" || fail "--site '$site': letters, digits, '.', '_', '-' (at most 64)"
fi
if [ -n "$domain" ]; then
  [[ $domain =~ ^[0-9]{1,3}$ ]] && [ "$domain" -le 232 ] || fail "--domain $domain: a DDS domain ID is 0..232"
fi

# Nothing is written before every check has passed: a refused run leaves DIR
# as it was (absent, on a first run).
out=$(realpath -m -- "$out")
[ ! -e "$out" ] || [ -d "$out" ] || fail "--out $out: exists and is not a directory"
id_ca=$out/ca/identity
perm_ca=$out/ca/permissions
roster=$out/roster     # "ROLE NAME [RACK,...]" per identity of the site (no racks: every rack)
site_conf=$out/site.conf

# --- the site: its domain and name, kept from the first run ------------------
# The name is in every subject: it changes only with new CAs, which issue
# every identity of the site again.
stored_domain="" stored_site=""
if [ -f "$site_conf" ]; then
  stored_domain=$(sed -n 's/^domain=//p' "$site_conf")
  stored_site=$(sed -n 's/^site=//p' "$site_conf")
fi
if [ -n "$stored_site" ] && [ -n "$site" ] && [ "$site" != "$stored_site" ] && [ "$new_ca" = 0 ]; then
  fail "$out belongs to site '$stored_site', not '$site' (the site name is in every subject: it changes only with --new-ca)"
fi
site=${site:-${stored_site:-dnbridge-site}}
if [ -z "$domain" ]; then
  domain=$stored_domain
  [ -n "$domain" ] || fail "--domain ID is required on the first run"
elif [ -n "$stored_domain" ] && [ "$domain" != "$stored_domain" ]; then
  echo "domain changes from $stored_domain to $domain: the documents are made for domain $domain"
fi

# --- the roster: every identity of the site and its role -----------------------
role_of() { [ ! -f "$roster" ] || awk -v n="$1" '$2 == n { print $1 }' "$roster"; }
declare -A asked=()
for i in "${!add_names[@]}"; do
  name=${add_names[$i]} role=${add_roles[$i]}
  known=${asked[$name]:-$(role_of "$name")}
  if [ -n "$known" ] && [ "$known" != "$role" ]; then
    fail "$name is already a $known of this site (a name has one role)"
  fi
  asked[$name]=$role
done
for name in "${renew[@]}"; do
  [ -n "${asked[$name]:-$(role_of "$name")}" ] || fail "--renew $name: no such identity in $roster"
done
if [ "$new_ca" = 0 ]; then
  for dir in "$id_ca" "$perm_ca"; do
    if [ -f "$dir/ca.pem" ] && [ ! -f "$dir/ca.key" ]; then
      fail "$dir/ca.pem exists without its ca.key: refusing to go on (--new-ca makes new CAs)"
    fi
  done
fi

umask 077  # private keys readable by their owner only
mkdir -p "$out"
touch "$roster"
for i in "${!add_names[@]}"; do
  name=${add_names[$i]}
  [ -n "$(role_of "$name")" ] || echo "${add_roles[$i]} $name" >>"$roster"
  # New racks replace the name's racks; "*" is every rack (no third field).
  if [ -n "${add_racks[$i]}" ]; then
    racks=${add_racks[$i]#=}
    [ "$racks" != "*" ] || racks=""
    awk -v n="$name" -v r="$racks" '$2 == n { $0 = $1 " " $2 (r == "" ? "" : " " r) } { print }' \
      "$roster" >"$roster.new"
    mv "$roster.new" "$roster"
  fi
done
printf 'site=%s\ndomain=%s\n' "$site" "$domain" >"$site_conf"

# --- the CAs -------------------------------------------------------------------
# --new-ca: the old PKI is kept aside, never deleted; every identity is
# issued again.
if [ "$new_ca" = 1 ] && { [ -e "$out/ca" ] || [ -e "$out/hosts" ]; }; then
  previous=$out/previous-$(date -u +%Y%m%dT%H%M%SZ)
  mkdir "$previous"
  for f in ca hosts governance.xml governance.p7s permissions.xml permissions.p7s; do
    if [ -e "$out/$f" ]; then mv "$out/$f" "$previous/"; fi
  done
  echo "previous PKI moved to $previous"
fi
# A self-signed CA certificate and key (prime256v1, which Cyclone's plugins
# take). The permissions CA signs the documents itself: S/MIME verification
# wants digitalSignature in its key usage.
make_ca() {
  local dir=$1 cn=$2 usage=$3
  if [ -f "$dir/ca.pem" ]; then
    return  # its key is there: checked before anything was written
  fi
  mkdir -p "$dir/issued"
  openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:prime256v1 -out "$dir/ca.key" 2>/dev/null
  openssl req -x509 -new -key "$dir/ca.key" -sha256 -days "$ca_days" \
    -subj "/O=$site/CN=$cn" \
    -addext "basicConstraints=critical,CA:TRUE" \
    -addext "keyUsage=critical,$usage" \
    -out "$dir/ca.pem"
  : >"$dir/index.txt"
  echo 1000 >"$dir/serial"
  # openssl ca's configuration: what the identity certificates get.
  cat >"$dir/openssl.cnf" <<EOF
[ ca ]
default_ca = site_ca
[ site_ca ]
dir = $dir
database = \$dir/index.txt
serial = \$dir/serial
new_certs_dir = \$dir/issued
certificate = \$dir/ca.pem
private_key = \$dir/ca.key
default_md = sha256
policy = site_policy
unique_subject = no
copy_extensions = none
email_in_dn = no
x509_extensions = identity
[ site_policy ]
organizationName = match
organizationalUnitName = supplied
commonName = supplied
[ identity ]
basicConstraints = critical,CA:FALSE
keyUsage = critical,digitalSignature,keyAgreement
subjectKeyIdentifier = hash
authorityKeyIdentifier = keyid
EOF
  echo "made $cn: $dir/ca.pem"
}
make_ca "$id_ca" "$site identity CA" keyCertSign,cRLSign
make_ca "$perm_ca" "$site permissions CA" digitalSignature,keyCertSign,cRLSign

# --- identities ----------------------------------------------------------------
# Subject, as RFC 2253 prints it (what the permissions grant names).
subject_of() { echo "CN=$2,OU=$1,O=$site"; }

issue() {
  local role=$1 name=$2 host=$out/hosts/$2
  mkdir -p "$host"
  openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:prime256v1 -out "$host/key.pem.new" 2>/dev/null
  openssl req -new -key "$host/key.pem.new" -subj "/O=$site/OU=$role/CN=$name" -out "$host/request.csr"
  openssl ca -batch -notext -config "$id_ca/openssl.cnf" -days "$days" \
    -in "$host/request.csr" -out "$host/cert.pem.new" 2>"$host/openssl-ca.log" ||
    { cat "$host/openssl-ca.log" >&2; fail "openssl ca could not issue $name"; }
  mv "$host/key.pem.new" "$host/key.pem"
  mv "$host/cert.pem.new" "$host/cert.pem"
  rm -f "$host/request.csr" "$host/openssl-ca.log"
  echo "issued $role $name: $host/cert.pem ($(openssl x509 -in "$host/cert.pem" -noout -enddate))"
}

while read -r role name _; do
  [ -n "$name" ] || continue
  host=$out/hosts/$name
  renewing=0
  for r in "${renew[@]}"; do [ "$r" = "$name" ] && renewing=1; done
  if [ -f "$host/cert.pem" ] && [ "$renewing" = 0 ]; then continue; fi
  issue "$role" "$name"
done <"$roster"

# --- governance: one domain rule, every dnbridge topic protected ---------------
# Only participants authenticated by the identity CA join (no unauthenticated
# participants, join access control on); discovery and liveliness are
# encrypted, every RTPS message is signed, topic data is encrypted and its
# submessages signed; read and write access is checked for every topic, so
# a topic no grant names is denied.
cat >"$out/governance.xml" <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<!-- dnbridge site $site, DDS domain $domain: made by make-site-pki.sh -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains>
        <id>$domain</id>
      </domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>SIGN</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>SIGN</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF

# --- permissions: one grant per identity, by role --------------------------------
topics() { for t in "$@"; do echo "            <topic>dnbridge/$t</topic>"; done; }
# The state topics are in the default partition; commands, requests and
# replies in their rack's, "dnbridge/RACK" (every rack's: "dnbridge/*"),
# and, for every rack, in the default partition too, where bridges and
# supervisors of versions before partitions have them (an upgrade goes rack
# by rack); DeviceCommand, newer than partitions, in the racks' only.
state_topics() { topics PumpState DeviceState NodeStatus PortStatus; }
publish_of() {
  case $1 in
    bridge) state_topics ;;
  esac
}
publish_in_racks_of() {
  case $1 in
    bridge) topics ExplicitReply BusScanReply ReloadReply ;;
    supervisor) topics PumpCommand DeviceCommand ExplicitRequest BusScanRequest ReloadRequest ;;
  esac
}
subscribe_of() {
  case $1 in
    supervisor | monitor) state_topics ;;
  esac
}
subscribe_in_racks_of() {
  case $1 in
    bridge) topics PumpCommand DeviceCommand ExplicitRequest BusScanRequest ReloadRequest ;;
    supervisor)
      topics ExplicitReply PumpCommand DeviceCommand ExplicitRequest BusScanRequest BusScanReply \
        ReloadRequest ReloadReply
      ;;
  esac
}
# emit KIND TOPICS [PARTITION...]: a <publish> or <subscribe> rule of TOPICS
# (none: nothing), in those partitions (none: the default partition).
emit() {
  [ -n "$2" ] || return 0
  printf '        <%s>\n          <topics>\n%s\n          </topics>\n' "$1" "$2"
  if (($# > 2)); then
    local p
    echo "          <partitions>"
    for p in "${@:3}"; do echo "            <partition>$p</partition>"; done
    echo "          </partitions>"
  fi
  printf '        </%s>\n' "$1"
}
# rule KIND TOPICS [RACKS]: with RACKS ("*" or RACK,...), in those racks'
# partitions; for "*" in the default partition too, but for the topics
# that came after partitions (DeviceCommand): no version has them there.
# Without RACKS, in the default partition.
rule() {
  if [ -z "${3:-}" ]; then
    emit "$1" "$2"
  elif [ "$3" = "*" ]; then
    emit "$1" "$(grep -v '>dnbridge/DeviceCommand<' <<<"$2" || true)" "" "dnbridge/*"
    emit "$1" "$(grep '>dnbridge/DeviceCommand<' <<<"$2" || true)" "dnbridge/*"
  else
    local r partitions=()
    IFS=, read -r -a rule_racks <<<"$3"
    for r in "${rule_racks[@]}"; do partitions+=("dnbridge/$r"); done
    emit "$1" "$2" "${partitions[@]}"
  fi
}
# openssl prints "notBefore=Nov 22 10:00:00 2026 GMT"; a grant wants ISO 8601.
iso_date() { date -u -d "${1#*=}" +%Y-%m-%dT%H:%M:%SZ; }
{
  cat <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<!-- dnbridge site $site, DDS domain $domain: made by make-site-pki.sh -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
EOF
  while read -r role name racks; do
    [ -n "$name" ] || continue
    racks=${racks:-*}
    cert=$out/hosts/$name/cert.pem
    # The grant is valid as long as the identity's certificate.
    not_before=$(iso_date "$(openssl x509 -in "$cert" -noout -startdate)")
    not_after=$(iso_date "$(openssl x509 -in "$cert" -noout -enddate)")
    pub=$(publish_of "$role")
    pub_racks=$(publish_in_racks_of "$role")
    sub=$(subscribe_of "$role")
    sub_racks=$(subscribe_in_racks_of "$role")
    cat <<EOF
    <grant name="$role-$name">
      <subject_name>$(subject_of "$role" "$name")</subject_name>
      <validity>
        <not_before>$not_before</not_before>
        <not_after>$not_after</not_after>
      </validity>
      <allow_rule>
        <domains>
          <id>$domain</id>
        </domains>
EOF
    rule publish "$pub"
    rule publish "$pub_racks" "$racks"
    rule subscribe "$sub"
    rule subscribe "$sub_racks" "$racks"
    cat <<EOF
      </allow_rule>
      <default>DENY</default>
    </grant>
EOF
  done <"$roster"
  echo "  </permissions>"
  echo "</dds>"
} >"$out/permissions.xml"

# S/MIME with the text header, as Cyclone's access control plugin verifies it.
sign() {
  openssl smime -sign -text -in "$out/$1.xml" -out "$out/$1.p7s" \
    -signer "$perm_ca/ca.pem" -inkey "$perm_ca/ca.key"
}
sign governance
sign permissions

# --- what each host gets ------------------------------------------------------------
while read -r role name racks; do
  [ -n "$name" ] || continue
  host=$out/hosts/$name
  cp "$id_ca/ca.pem" "$host/identity_ca.pem"
  cp "$perm_ca/ca.pem" "$host/permissions_ca.pem"
  cp "$out/governance.p7s" "$out/permissions.p7s" "$host/"
  scope=""
  [ "$role" = monitor ] || scope="; racks: ${racks:-every rack}"
  cat >"$host/security.toml" <<EOF
# DDS Security of $role $name (site $site, domain $domain$scope).
# Relative paths are relative to this file's directory.
[security]
identity_ca = "identity_ca.pem"
certificate = "cert.pem"
private_key = "key.pem"
permissions_ca = "permissions_ca.pem"
governance = "governance.p7s"
permissions = "permissions.p7s"
EOF
  chmod 644 "$host"/*.pem "$host"/*.p7s "$host/security.toml"
  chmod 600 "$host/key.pem"
done <"$roster"

echo "site $site, domain $domain: $(wc -l <"$roster") identities; governance.p7s and permissions.p7s signed"
