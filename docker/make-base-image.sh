#!/usr/bin/env bash
# Build a Debian bookworm base image without an image registry: debootstrap a minbase root
# file system from this machine's own apt mirror and import it into podman's local store.
# The result stands in for the registry's debian:bookworm in docker/Dockerfile (build-arg BASE_IMAGE).
#
#   sudo docker/make-base-image.sh [image-name]          default image name: tsg-base:bookworm
# Environment: TSG_DEBIAN_MIRROR  archive URI (default: the first URI of this machine's apt
#                                 sources that serves bookworm)
#              TSG_DEBIAN_SECURITY_MIRROR  security archive URI (default: this machine's apt
#                                 source for bookworm-security, else <mirror>-security)
#              TSG_ROOTFS_DIR     where the root file system is staged (default /var/tmp/tsg-base-rootfs;
#                                 removed after a successful import)
# Needs: root, debootstrap, podman.
set -euo pipefail
image="${1:-tsg-base:bookworm}"
rootfs="${TSG_ROOTFS_DIR:-/var/tmp/tsg-base-rootfs}"

fail() { printf '[make-base-image] ERROR: %s\n' "$*" >&2; exit 1; }
step() { printf '[make-base-image] %s\n' "$*" >&2; }

[ "$(id -u)" -eq 0 ] || fail "debootstrap needs root (run with sudo)"
for tool in debootstrap podman; do
  command -v "$tool" >/dev/null || fail "$tool not found (apt-get install $tool)"
done

# The archive URIs: the ones apt on this machine already uses for a suite, so no host name is
# baked into the project. deb822 (.sources) files first, then the one-line sources.list format.
uri_for_suite() {
  local suite="$1" f
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    awk -v want="$suite" 'BEGIN { RS = ""; FS = "\n" }
         { uris = ""; suite = 0
           for (i = 1; i <= NF; i++) {
             if ($i ~ /^URIs:/)   { sub(/^URIs:[ \t]*/, "", $i); split($i, u, /[ \t]+/); uris = u[1] }
             if ($i ~ /^Suites:/) { n = split($i, s, /[ \t]+/); for (j = 2; j <= n; j++) if (s[j] == want) suite = 1 }
           }
           if (suite && uris != "") { print uris; exit } }' "$f"
  done
  [ -f /etc/apt/sources.list ] && awk -v want="$suite" '$1 == "deb" && $3 == want { print $2; exit }' /etc/apt/sources.list
  return 0
}
mirror="${TSG_DEBIAN_MIRROR:-$(uri_for_suite bookworm | head -n 1)}"
[ -n "$mirror" ] || fail "no bookworm archive found in /etc/apt; set TSG_DEBIAN_MIRROR=<archive URI>"
security="${TSG_DEBIAN_SECURITY_MIRROR:-$(uri_for_suite bookworm-security | head -n 1)}"
security="${security:-${mirror%/}-security}"
step "archive: $mirror   security archive: $security"

rm -rf "$rootfs"
mkdir -p "$rootfs"
step "debootstrap --variant=minbase bookworm into $rootfs"
debootstrap --variant=minbase --include=ca-certificates bookworm "$rootfs" "$mirror" > "$rootfs.debootstrap.log" 2>&1 \
  || { tail -n 20 "$rootfs.debootstrap.log" >&2; fail "debootstrap failed (full log: $rootfs.debootstrap.log)"; }

# apt sources inside the image: the same archive with the updates and security suites that the
# registry's debian:bookworm image carries.
rm -f "$rootfs/etc/apt/sources.list"
cat > "$rootfs/etc/apt/sources.list.d/debian.sources" <<SOURCES
Types: deb
URIs: $mirror
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: $security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SOURCES
# keep the image small, as the registry image does: no cached .debs or package lists
rm -rf "$rootfs"/var/cache/apt/archives/*.deb "$rootfs"/var/lib/apt/lists/* "$rootfs"/var/log/*.log

step "importing into podman as $image"
tar --numeric-owner -C "$rootfs" -c . | podman import --change 'CMD ["/bin/bash"]' - "$image" >/dev/null \
  || fail "podman import failed"
rm -rf "$rootfs"
podman image inspect --format '{{.Id}} {{.Size}}' "$image" >&2
step "done: $image"
