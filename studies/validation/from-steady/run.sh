#!/usr/bin/env bash
# The seed paper's sensitivity rows (Table 4) and its particle-particle / particle-geometry splits
# (Figs. 13-15) at demo scale, from the steady states the main job starts from
# (cases/states/periodic-demo: fills 1-3 at t = 1.5 s after the fill, when the demo's flux and hold-up
# are steady): each setting changes its coefficients at t = 1.5 s and runs T_SAMPLE s (0.5); the
# analysis windows start after the detected steady start of the changed runs. The reference is the
# same continuation with nothing changed. One run at a time on one core (≈ 3.5 min each), in the
# order below: static friction split and applied to both first (the paper's central finding), then
# rolling friction and restitution likewise. A finished run (DONE) is skipped. The runs directory is
# a sweep directory (runs.txt, DONE/FAILED markers), so that the report is tsg-sweep's:
#   studies/validation/from-steady/run.sh [RUNS_DIR]       (default runs/from-steady)
#   tsg-sweep report RUNS_DIR --out studies/validation/from-steady --start auto --parts 4
# Two rows cannot start from these states and stay in studies/validation/steady and steady-psd: the
# PSD width changes the fill, and high cohesion the contact model, whose per-contact history the
# restart file keeps (the runner refuses both with --from-state).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
runs="${1:-$root/runs/from-steady}"
sample="${T_SAMPLE:-0.5}"
export TSG_LMP="${TSG_LMP:-$root/build/lmp}"
settings=(
  "reference:"
  "mus_pg-0.1:mus_pg 0.1"
  "mus_pp-0.1:mus_pp 0.1"
  "static-friction-0.1:mus_pp 0.1 mus_pg 0.1"
  "mur_pp-0.2:mur_pp 0.2"
  "mur_pg-0.2:mur_pg 0.2"
  "rolling-friction-0.2:mur_pp 0.2 mur_pg 0.2"
  "restitution-0.9:e_pp 0.9 e_pg 0.9"
  "e_pp-0.9:e_pp 0.9"
  "e_pg-0.9:e_pg 0.9"
  "restitution-0.1:e_pp 0.1 e_pg 0.1"
)
mkdir -p "$runs"
: > "$runs/runs.txt"
for entry in "${settings[@]}"; do
  name="${entry%%:*}"
  variables=()
  for pair in $(echo "${entry#*:}" | xargs -n2 | tr ' ' '='); do variables+=(-v "${pair%=*}" "${pair#*=}"); done
  for seed in 1 2 3; do
    out="$runs/$name/seed-$seed"
    echo "$name/seed-$seed" >> "$runs/runs.txt"
    if [ -f "$out/DONE" ]; then continue; fi
    mkdir -p "$out"
    rm -f "$out/FAILED"
    status=0
    "$root/.venv/bin/tsg-run-case" periodic --scale demo --from-state "$root/cases/states/periodic-demo/seed-$seed" \
      --np 1 --out "$out" -v t_sample "$sample" "${variables[@]}" > "$out.out" 2>&1 || status=$?
    if [ "$status" = 0 ]; then touch "$out/DONE"; else echo "$status" > "$out/FAILED"; echo "[from-steady] $out failed" >&2; fi
  done
done
