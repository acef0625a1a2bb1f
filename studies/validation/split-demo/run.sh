#!/usr/bin/env bash
# The paper's particle-particle / particle-geometry split of static friction (Figs. 13-15) at demo
# scale, from the steady states the main job starts from (cases/states/periodic-demo, t = 1.5 s
# after the fill): each setting changes one coefficient at t = 1.5 s and runs T_SAMPLE s; the
# analysis windows start after the detected steady start of the changed run. One run at a time
# (one core). The reference is the main job's three fills (./tsg run: runs/periodic-demo).
#   studies/validation/split-demo/run.sh [RUNS_DIR]       (default runs/split-demo)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
runs="${1:-$root/runs/split-demo}"
sample="${T_SAMPLE:-0.5}"
export TSG_LMP="${TSG_LMP:-$root/build/lmp}"
for setting in "mus_pg 0.1" "mus_pp 0.1"; do
  set -- $setting
  for seed in 1 2 3; do
    out="$runs/$1-$2/seed-$seed"
    if grep -q TSG-DONE "$out/log.lammps" 2>/dev/null; then continue; fi
    "$root/.venv/bin/tsg-run-case" periodic --scale demo --from-state "$root/cases/states/periodic-demo/seed-$seed" \
      --np 1 --out "$out" -v t_sample "$sample" -v "$1" "$2" > "$out.out" 2>&1 || echo "[split] $out failed" >&2
  done
done
