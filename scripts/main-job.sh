#!/usr/bin/env bash
# The main job: run the demo case with our lmp and print a short summary.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$(cd "$root" && realpath "${1:-build}")"
out="$root/runs/main"
mkdir -p "$out"
printf '\n==> [run] stock settling case (cases/stock/in.settle) in %s\n' "$out"
PYTHONPATH="$root/analysis" exec "$root/.venv/bin/python" -m tsg_analysis.main_job \
  --lmp "$build_dir/lmp" --input "$root/cases/stock/in.settle" --workdir "$out"
