#!/usr/bin/env bash
# The main job: the periodic ConsiGma-1 kneading-block case at demo scale on 2 MPI ranks
# (tsg-run-case, cases/run_case.py; docs/cases.md), then its summary table.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$(cd "$root" && realpath "${1:-build}")"
printf '\n==> [run] periodic kneading-block case, demo scale (cases/in.tsg_periodic)\n'
TSG_LMP="$build_dir/lmp" exec "$root/.venv/bin/tsg-run-case" periodic --scale demo \
  --np "${TSG_RUN_NP:-2}" --out "$root/runs/periodic-demo"
