#!/usr/bin/env bash
# Makes /tmp/pydds the Cyclone DDS 11.0.1 bundle BUNDLE (a .tgz holding the
# Python virtual environment pydds/, which works at /tmp/pydds only; see
# /work/shared/tools/README.md beside it): unpacked unless /tmp/pydds is
# already that bundle, as its stamp file (the .tgz's SHA-256) says. The
# Cyclone DDS 11 interoperability test runs it before each test.
#
#   bash cyclone11_bundle.sh BUNDLE
#
# Runs of it at the same time take turns (flock on /tmp/pydds.lock); the
# bundle is unpacked beside /tmp/pydds and renamed into place, so that
# /tmp/pydds is never a half-unpacked tree. Exit status 1, with a message,
# when BUNDLE is missing or does not hold a working Cyclone DDS 11.
set -euo pipefail

bundle=${1:?usage: cyclone11_bundle.sh BUNDLE}
dest=/tmp/pydds
stamp=$dest/.dnbridge-bundle-sha256

if [ ! -f "$bundle" ]; then
  echo "cyclone11_bundle.sh: the Cyclone DDS 11.0.1 bundle $bundle does not exist" \
       "(CMake cache variable DNBRIDGE_CYCLONE11_BUNDLE)" >&2
  exit 1
fi
sum=$(sha256sum "$bundle" | cut -d' ' -f1)

exec 9>/tmp/pydds.lock
if ! flock -w 60 9; then
  echo "cyclone11_bundle.sh: /tmp/pydds.lock still held after 60 s" >&2
  exit 1
fi

if [ "$(cat "$stamp" 2>/dev/null || true)" != "$sum" ]; then
  echo "cyclone11_bundle.sh: unpacking $bundle at $dest"
  work=$(mktemp -d /tmp/pydds.unpack.XXXXXX)
  trap 'rm -rf "$work"' EXIT
  tar xzf "$bundle" -C "$work"
  if [ ! -x "$work/pydds/bin/python" ]; then
    echo "cyclone11_bundle.sh: $bundle holds no pydds/bin/python" >&2
    exit 1
  fi
  echo "$sum" >"$work/pydds/.dnbridge-bundle-sha256"
  # What was at /tmp/pydds (another bundle, or one unpacked by hand) goes
  # aside, then the new tree takes its place.
  if [ -e "$dest" ] || [ -L "$dest" ]; then mv "$dest" "$work/previous"; fi
  mv "$work/pydds" "$dest"
fi

if ! out=$("$dest/bin/python" -c 'import cyclonedds, importlib.metadata as m; print(m.version("cyclonedds"))' 2>&1); then
  echo "cyclone11_bundle.sh: $dest/bin/python does not import cyclonedds: $out" >&2
  exit 1
fi
if [ "$out" != 11.0.1 ]; then
  echo "cyclone11_bundle.sh: $dest holds the Python binding $out, not 11.0.1" >&2
  exit 1
fi
