#!/usr/bin/env bash
# Fetch the upstream LIGGGHTS-PUBLIC 3.8.0 tree from Debian's source package `liggghts`,
# verify the tarball's SHA-256 and unpack it into the cache (outside the work tree).
# Idempotent: a verified tarball or an unpacked tree is reused; nothing is fetched twice.
#
#   scripts/fetch-liggghts.sh            -> prints the tree's path on the last line
#   TSG_CACHE_DIR=/path scripts/fetch-liggghts.sh
set -euo pipefail

cache_dir="${TSG_CACHE_DIR:-$HOME/.cache/tsg-dem}"
tarball_name="liggghts_3.8.0+repack1.orig.tar.xz"
tarball_sha256="c18721d9a870c5170f03b91e4f1ffe13335c66ed1f0ff2c64ebd3be91c37867a"
tree="$cache_dir/LIGGGHTS-PUBLIC-3.8.0"
tarball="$cache_dir/$tarball_name"

step() { printf '[fetch-liggghts] %s\n' "$*" >&2; }
fail() { printf '[fetch-liggghts] ERROR: %s\n' "$*" >&2; exit 1; }

mkdir -p "$cache_dir" || fail "cannot create cache directory $cache_dir (set TSG_CACHE_DIR to a writable place)"

if [ -f "$tree/.tsg-verified" ] && [ -f "$tree/src/lammps.cpp" ]; then
  step "upstream tree already unpacked and verified: $tree"
  echo "$tree"; exit 0
fi

verify() { [ -f "$tarball" ] && echo "$tarball_sha256  $tarball" | sha256sum --check --status; }

if verify; then
  step "cached tarball verified: $tarball"
else
  if [ -f "$tarball" ]; then
    step "cached tarball fails its SHA-256 check; fetching it again"
    rm -f "$tarball"
  fi
  command -v apt-get >/dev/null || fail "apt-get not found: this fetch needs Debian's apt. Download $tarball_name yourself and pass -DLIGGGHTS_SOURCE_DIR=<unpacked tree> to cmake."
  command -v curl >/dev/null || fail "curl not found (apt-get install curl), needed to download $tarball_name"
  # deb-src entries derived from this machine's own apt sources (same URIs and suites),
  # kept in a private apt state directory so the system configuration is not touched.
  apt_dir="$cache_dir/apt"
  mkdir -p "$apt_dir/lists/partial" "$apt_dir/sources.list.d"
  rm -f "$apt_dir/sources.list.d/"*
  found_sources=0
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    sed -E 's/^Types:.*$/Types: deb-src/' "$f" > "$apt_dir/sources.list.d/$(basename "$f")"
    found_sources=1
  done
  if [ -f /etc/apt/sources.list ]; then
    grep -E '^deb ' /etc/apt/sources.list | sed 's/^deb /deb-src /' > "$apt_dir/sources.list.d/from-sources-list.list" || true
    [ -s "$apt_dir/sources.list.d/from-sources-list.list" ] && found_sources=1
  fi
  [ "$found_sources" = 1 ] || fail "no apt sources found in /etc/apt to derive deb-src entries from"
  apt_opts=(-o Dir::Etc::SourceList=/dev/null -o "Dir::Etc::SourceParts=$apt_dir/sources.list.d"
            -o "Dir::State::Lists=$apt_dir/lists" -o Debug::NoLocking=1 -o APT::Sandbox::User=root)
  step "updating the source-package index (private apt state in $apt_dir)"
  # apt-get update exits 0 even when every index failed to download: judge its messages
  update_log=$(apt-get "${apt_opts[@]}" update 2>&1) && ! grep -qiE 'failed to (fetch|download)|could not' <<<"$update_log" \
    || { printf '%s\n' "$update_log" | tail -n 3 >&2
         fail "apt-get update for deb-src failed: no network, or the mirror is unreachable. Re-run when online."; }
  uri=$(apt-get "${apt_opts[@]}" source --print-uris liggghts 2>/dev/null \
        | awk -v n="$tarball_name" '$2 == n { gsub("\047", "", $1); print $1 }') || true
  [ -n "$uri" ] || fail "Debian's source index does not list $tarball_name (package 'liggghts' missing from the configured suites?)"
  step "downloading $tarball_name"
  curl -fsSL --retry 3 -o "$tarball.part" "$uri" || fail "download of $tarball_name failed (network?). Re-run to resume."
  mv "$tarball.part" "$tarball"
  verify || { rm -f "$tarball"; fail "SHA-256 mismatch for $tarball_name (expected $tarball_sha256): the file was removed; re-run to fetch again"; }
  step "tarball verified (SHA-256 $tarball_sha256)"
fi

step "unpacking into $tree"
rm -rf "$tree" "$tree.part"
mkdir -p "$tree.part"
tar -xJf "$tarball" -C "$tree.part" --strip-components=1 || fail "unpacking $tarball failed"
[ -f "$tree.part/src/lammps.cpp" ] || fail "unpacked tarball has no src/lammps.cpp"
touch "$tree.part/.tsg-verified"
mv "$tree.part" "$tree"
echo "$tree"
