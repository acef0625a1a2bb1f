#!/usr/bin/env bash
# One set-up for a fresh Debian 12 machine (also used by docker/Dockerfile and .ci/run).
# Idempotent and resumable: every step checks what is already there and only does what is missing.
#
#   scripts/setup.sh            all steps (the first run also makes the paper-scale inputs of the
#                               periodic and non-periodic case files: the fill took 3.6 min on 2
#                               lightly loaded cores, docs/cluster.md)
# Environment: TSG_CACHE_DIR (default ~/.cache/tsg-dem), LIGGGHTS_SOURCE_DIR (use your own tree),
#              TSG_BUILD_DIR (default build), TSG_JOBS (default: number of cores)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
build_dir="${TSG_BUILD_DIR:-build}"
jobs="${TSG_JOBS:-$(nproc)}"

step() { printf '\n==> [setup] %s\n' "$*"; }
fail() { printf '\n[setup] ERROR in step "%s": %s\n' "$current_step" "$*" >&2; exit 1; }
current_step=""

# ---- 1. system packages -------------------------------------------------------------------------
current_step="system packages"
step "$current_step"
# compilers and build tools; MPI; VTK 9 (MPI-enabled); tests; X/GL libraries that gmsh's wheel and
# off-screen pyvista load even without a display
packages=(build-essential cmake patch curl ca-certificates xz-utils ccache clang-format
          libopenmpi-dev openmpi-bin libvtk9-dev libgtest-dev libbenchmark-dev
          python3 python3-venv
          libglu1-mesa libgl1 libegl1 libosmesa6 libxrender1 libxcursor1 libxft2 libxinerama1 libxi6
          libxkbcommon0 libfontconfig1)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "all ${#packages[@]} Debian packages present"
else
  echo "installing: ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  command -v apt-get >/dev/null || fail "apt-get not found; install these packages yourself: ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq || fail "apt-get update failed (no network?). Re-run to resume."
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" \
    || fail "apt-get install failed for: ${missing[*]}. Re-run to resume."
fi

# ---- 2. upstream LIGGGHTS source ------------------------------------------------------------------
current_step="LIGGGHTS-PUBLIC 3.8.0 source"
step "$current_step"
if [ -n "${LIGGGHTS_SOURCE_DIR:-}" ]; then
  [ -f "$LIGGGHTS_SOURCE_DIR/src/lammps.cpp" ] \
    || fail "LIGGGHTS_SOURCE_DIR=$LIGGGHTS_SOURCE_DIR has no src/lammps.cpp: point it at the directory that contains src/"
  tree="$LIGGGHTS_SOURCE_DIR"
  echo "using your tree: $tree"
else
  tree="$(scripts/fetch-liggghts.sh | tail -n 1)" || fail "fetching the upstream source failed (see the message above)"
fi

# ---- 3. Python environment ------------------------------------------------------------------------
current_step="Python virtual environment (.venv)"
step "$current_step"
stamp=".venv/.requirements.sha256"
want="$(cat requirements.txt pyproject.toml | sha256sum | cut -d' ' -f1)"
if [ -x .venv/bin/python ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
  echo ".venv is up to date with requirements.txt and pyproject.toml"
else
  [ -x .venv/bin/python ] || /usr/bin/python3 -m venv .venv || fail "python3 -m venv failed (apt-get install python3-venv)"
  .venv/bin/python -m pip install -q --upgrade pip || fail "pip could not upgrade itself (no network?). Re-run to resume."
  .venv/bin/python -m pip install -q -r requirements.txt || fail "pip install -r requirements.txt failed. Re-run to resume."
  # the project's packages (tsg_analysis, tsg_meshes, tsg_cases) and their commands (tsg-run-case,
  # tsg-meshes, ...), editable: edits under analysis/, meshes/ and cases/ take effect at once
  .venv/bin/python -m pip install -q --no-deps -e . \
    || fail "pip install -e . failed (see pyproject.toml). Re-run to resume."
  echo "$want" > "$stamp"
  echo ".venv ready"
fi

# ---- 4. configure and build lmp -------------------------------------------------------------------
current_step="build lmp"
step "$current_step ($build_dir, $jobs jobs)"
cmake -S . -B "$build_dir" -DLIGGGHTS_SOURCE_DIR="$tree" -DCMAKE_INSTALL_PREFIX="$root/install" > "$build_dir.configure.log" 2>&1 \
  || { tail -n 30 "$build_dir.configure.log" >&2; fail "cmake configure failed (full log: $build_dir.configure.log)"; }
start=$(date +%s)
set +e
cmake --build "$build_dir" -j "$jobs" 2>&1 | tee "$build_dir.build.log" | awk '/^\[ *[0-9]+%\]/ { if (++n % 25 == 1) print; next } /[Ee]rror/ { print }'
build_rc=${PIPESTATUS[0]}
set -e
[ "$build_rc" -eq 0 ] || fail "compilation failed (full log: $build_dir.build.log)"
[ -x "$build_dir/lmp" ] || fail "$build_dir/lmp was not produced"
echo "lmp ready: $build_dir/lmp (build step took $(( $(date +%s) - start )) s)"

# ---- 5. meshes -----------------------------------------------------------------------------------
current_step="screw and barrel meshes"
step "$current_step"
mesh_stamp="$build_dir/meshes/.generator.sha256"
mesh_want="$(cat meshes/tsg_meshes/*.py meshes/configs/*.spec | sha256sum | cut -d' ' -f1)"
if [ -f "$mesh_stamp" ] && [ "$(cat "$mesh_stamp")" = "$mesh_want" ]; then
  echo "meshes in $build_dir/meshes are up to date with meshes/"
else
  rm -rf "$build_dir/meshes"
  .venv/bin/python -m tsg_meshes build-all "$build_dir/meshes" \
    || fail "mesh generation failed (see the message above)"
  echo "$mesh_want" > "$mesh_stamp"
fi

# ---- 6. what the case files' defaults name (inputs run as typed) ---------------------------------
# `cd cases && lmp -in in.tsg_periodic` (and in.tsg_full, in.tsg_nonperiodic) runs the paper scale
# with no other step: the 1 um meshes, the periodic fill and the feed regions its defaults name
# (build/meshes, build/prepared; cases/prepared.py), and runs/ for its outputs (docs/cluster.md).
# The full case's 1 um feed regions (about 20 min and 2.6 GB here) are made on demand:
# `python -m tsg_cases.prepared defaults full` (in.tsg_full prints the command when they are missing).
current_step="paper-scale inputs of the case files"
step "$current_step"
if [ "$(realpath -m "$build_dir")" = "$root/build" ]; then
  mkdir -p runs
  .venv/bin/python -m tsg_cases.prepared defaults periodic nonperiodic \
    || fail "preparing the case files' default inputs failed (see the message above). Re-run to resume."
else
  echo "skipped: the case files' defaults name build/, not TSG_BUILD_DIR=$build_dir (pass -var mesh_dir/fill_file/feed_file)"
fi

step "set-up complete"
