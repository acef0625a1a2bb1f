#!/usr/bin/env bash
# The main job: the periodic ConsiGma-1 kneading-block case at demo scale, three fills (seeds 1-3)
# continued side by side from their kept states at the end of a 1.5 s start-up (cases/states/, made
# by `scripts/main-job.sh states`; cases/states.py), each sampled for ${TSG_MAIN_SAMPLE:-0.4} s on
# one rank; then the three combined into one summary table with 95 % intervals (tsg-analysis summary:
# replicas combined) and the report of the three (tsg-analysis report: profiles, mass-flow traces,
# RTDs, per-element residence times; docs/cases.md, "The main job").
#
#   scripts/main-job.sh [BUILD_DIR]          the main job (./tsg run)
#   scripts/main-job.sh states [BUILD_DIR]   make the kept states again (≈ 10 min per fill on one core)
# TSG_MAIN_SAMPLE: sampled time per fill, s; TSG_MAIN_OUT: the run directory (runs/periodic-demo).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
action=run
if [ "${1:-}" = states ]; then action=states; shift; fi
build_dir="$(cd "$root" && realpath "${1:-build}")"
states="$root/cases/states/periodic-demo"
seeds=(1 2 3)
startup=1.5        # s: the demo's flux and hold-up are steady from ≈ 1 s (docs/validation.md)
sample="${TSG_MAIN_SAMPLE:-0.4}"
export TSG_LMP="$build_dir/lmp"

if [ "$action" = states ]; then
  for seed in "${seeds[@]}"; do
    work="$root/runs/main-job-states/seed-$seed"
    printf '\n==> [states] fill %s: %s s of start-up, then its state\n' "$seed" "$startup"
    "$root/.venv/bin/tsg-run-case" periodic --scale demo --seed "$seed" --np 1 --out "$work" \
      -v t_startup "$startup" -v t_sample 0.005 -v write_state 1
    "$root/.venv/bin/python" -m tsg_cases.states keep "$work" "$states/seed-$seed"
  done
  exit 0
fi

run_dir="${TSG_MAIN_OUT:-$root/runs/periodic-demo}"
mkdir -p "$run_dir"
printf '\n==> [run] periodic kneading-block case, demo scale (cases/in.tsg_periodic): fills %s from their kept\n' "${seeds[*]}"
printf '    states at t = %s s (cases/states/periodic-demo), %s s sampled each, side by side on one rank each\n' "$startup" "$sample"
pids=()
for seed in "${seeds[@]}"; do
  "$root/.venv/bin/tsg-run-case" periodic --scale demo --from-state "$states/seed-$seed" --np 1 \
    --out "$run_dir/seed-$seed" -v t_sample "$sample" -v snapshot 1 > "$run_dir/seed-$seed.out" 2>&1 &
  pids+=($!)
done
while [ -n "$(jobs -rp)" ]; do   # one progress line per fill, about every 30 s
  sleep 30
  for seed in "${seeds[@]}"; do
    line=$(grep '^\[progress\]' "$run_dir/seed-$seed.out" | tail -1 | cut -d, -f1-2)
    [ -n "$line" ] && printf '    fill %s: %s\n' "$seed" "${line#\[progress\] }"
  done
done
failed=0
for i in "${!pids[@]}"; do
  if ! wait "${pids[$i]}"; then
    failed=1
    printf '[run] fill %s failed: %s\n' "${seeds[$i]}" "$(grep -m1 -E 'ERROR|failed' "$run_dir/seed-${seeds[$i]}.out" || echo "see $run_dir/seed-${seeds[$i]}.out")" >&2
  fi
done
[ $failed -eq 0 ] || exit 1
grep -h '^\[run\] done' "$run_dir"/seed-*.out | sed 's/^/    /'
printf '\n==> [run] summary: the three fills combined\n'
"$root/.venv/bin/tsg-analysis" summary "${seeds[@]/#/$run_dir/seed-}" | tee "$run_dir/summary.txt"
printf '\n==> [run] report\n'
"$root/.venv/bin/tsg-analysis" report "${seeds[@]/#/$run_dir/seed-}" --out "$run_dir/report"
printf '\n==> [run] summary in %s, report in %s\n' "$run_dir/summary.txt" "$run_dir/report"
