#!/usr/bin/env bash
# Build the TSG-DEM image with podman from a local debootstrap base and run the test command in it.
#
#   sudo docker/test-image.sh [ctest args]      e.g.  sudo docker/test-image.sh -L eepa
# Steps: 1. base image (docker/make-base-image.sh; skipped when it exists), 2. podman build of
# docker/Dockerfile, 3. `./tsg test [ctest args]` in a fresh container.
# Environment:
#   TSG_BASE_IMAGE   base image (default localhost/tsg-base:bookworm, made by make-base-image.sh
#                    when missing; any other name is pulled, e.g. debian:bookworm from a registry)
#   TSG_IMAGE        image name (default localhost/tsg-dem:latest)
#   TSG_CCACHE_DIR   a host ccache directory mounted at the image's ccache path during the build
#                    only (a speed-up: the image does not depend on it); unset: no mount
#   TSG_CA_BUNDLE    a CA bundle pip must trust during the build (a TLS-intercepting proxy's);
#                    default: $PIP_CERT of this shell; mounted read-only, not copied into the image
#   TSG_SKIP_BUILD=1 reuse an existing TSG_IMAGE;  TSG_SKIP_TESTS=1 build only
# Where the engine's default limits cannot be applied (sandboxes without CAP_SYS_RESOURCE, or with
# cgroup v1+v2 "hybrid" mounts that crun refuses), the script falls back to runc and to resource
# limits no higher than this shell's own, and says so.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
base="${TSG_BASE_IMAGE:-localhost/tsg-base:bookworm}"
image="${TSG_IMAGE:-localhost/tsg-dem:latest}"

step() { printf '\n==> [test-image] %s\n' "$*"; }
fail() { printf '[test-image] ERROR: %s\n' "$*" >&2; exit 1; }
command -v podman >/dev/null || fail "podman not found (apt-get install podman)"

# ---- 1. base image -------------------------------------------------------------------------------
step "base image $base"
if podman image exists "$base"; then
  echo "present"
elif [[ "$base" == localhost/* ]]; then
  docker/make-base-image.sh "${base#localhost/}"
else
  podman pull "$base" || fail "cannot pull $base (no registry? leave TSG_BASE_IMAGE unset to make a local base)"
fi

# ---- engine options: defaults first, the sandbox fallback only when the defaults cannot run -------
engine_opts=()
if ! probe=$(podman run --rm "$base" true 2>&1); then
  echo "podman run with default options failed: $probe"
  command -v runc >/dev/null || fail "and runc, the fallback runtime, is not installed (apt-get install runc)"
  # podman lowers its own RLIMIT_NPROC to 32768 when it cannot raise it; a container may not exceed it
  nproc_max=$(ulimit -Hu); [ "$nproc_max" = unlimited ] || [ "$nproc_max" -gt 32768 ] && nproc_max=32768
  nofile_max=$(ulimit -Hn); [ "$nofile_max" = unlimited ] && nofile_max=1048576
  engine_opts=(--runtime runc --ulimit "nofile=$nofile_max:$nofile_max" --ulimit "nproc=$nproc_max:$nproc_max")
  probe=$(podman run --rm "${engine_opts[@]}" "$base" true 2>&1) \
    || fail "podman cannot run containers here, even with ${engine_opts[*]}: $probe"
  echo "using: ${engine_opts[*]}"
fi

# ---- 2. image ------------------------------------------------------------------------------------
if [ "${TSG_SKIP_BUILD:-0}" = 1 ]; then
  step "reusing image $image"
  podman image exists "$image" || fail "TSG_SKIP_BUILD=1 but image $image does not exist"
else
  build_opts=("${engine_opts[@]}" --build-arg "BASE_IMAGE=$base" -f docker/Dockerfile -t "$image")
  if [ -n "${TSG_CCACHE_DIR:-}" ]; then
    [ -d "$TSG_CCACHE_DIR" ] || fail "TSG_CCACHE_DIR=$TSG_CCACHE_DIR is not a directory"
    build_opts+=(--volume "$TSG_CCACHE_DIR:/root/.cache/ccache")
  fi
  ca_bundle="${TSG_CA_BUNDLE-${PIP_CERT:-}}"
  if [ -n "$ca_bundle" ]; then
    [ -f "$ca_bundle" ] || fail "TSG_CA_BUNDLE=$ca_bundle is not a file"
    build_opts+=(--volume "$ca_bundle:/run/tsg-ca-bundle.crt:ro" --build-arg PIP_CERT=/run/tsg-ca-bundle.crt)
  fi
  step "podman build ${build_opts[*]} ."
  start=$(date +%s)
  podman build "${build_opts[@]}" . || fail "podman build failed (see above)"
  echo "image built in $(( $(date +%s) - start )) s"
fi
podman image inspect --format 'image {{.Id}}: {{.Size}} bytes' "$image"

# ---- 3. tests ------------------------------------------------------------------------------------
[ "${TSG_SKIP_TESTS:-0}" = 1 ] && exit 0
step "podman run --rm $image ./tsg test $*"
start=$(date +%s)
set +e
podman run --rm "${engine_opts[@]}" "$image" ./tsg test "$@"
rc=$?
set -e
echo "tests in the container took $(( $(date +%s) - start )) s, exit status $rc"
exit $rc
