#!/usr/bin/env bash
# The main job: the periodic ConsiGma-1 kneading-block case at demo scale on 2 MPI ranks
# (tsg-run-case, cases/run_case.py; docs/cases.md), its summary table with 95 % intervals, then the
# full report (tsg-analysis report: profiles with intervals, mass-flow traces, RTD where resolved).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$(cd "$root" && realpath "${1:-build}")"
run_dir="$root/runs/periodic-demo"
printf '\n==> [run] periodic kneading-block case, demo scale (cases/in.tsg_periodic)\n'
TSG_LMP="$build_dir/lmp" "$root/.venv/bin/tsg-run-case" periodic --scale demo -v snapshot 1 \
  --np "${TSG_RUN_NP:-2}" --out "$run_dir"
printf '\n==> [run] report\n'
"$root/.venv/bin/tsg-analysis" report "$run_dir" --out "$run_dir/report"
printf '\n==> [run] report written to %s\n' "$run_dir/report"
