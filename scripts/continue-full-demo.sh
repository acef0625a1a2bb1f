#!/usr/bin/env bash
# Continue the full granulator at 1.5 mm (docs/validation.md, "Periodic against full") from the state
# kept in docs/validation/full-demo-d15/ (its latest restart file and outputs, compressed), in
# segments that each pick up from the latest restart file (cases/slurm/segment.sh).
#
#   scripts/continue-full-demo.sh [RANKS]             # default 2; run it again to go on after a stop
#   scripts/continue-full-demo.sh RANKS --until T     # end at t = T s with a snapshot of the particles
#                                                     # still inside (residence records "inside")
#   scripts/continue-full-demo.sh --keep              # compress the run's latest state back into docs/
#
# The run stops by itself at t_sample after its (spurious, at 0.99 s) in-script steady state; the
# steady window is chosen afterwards: python -m tsg_analysis domains ... --full-start auto (it refuses a
# record that is not yet steady for long enough). The passes of the section (the RTDs) need the
# snapshot at the end: stop a running continuation, --keep, end it with --until (the finished run has
# no restart file left: segment.sh removes them), --keep again (the outputs; the restart file of the
# first --keep stays, and a later continuation from it drops the records written after it).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
kept="$repo/docs/validation/full-demo-d15"
out="$repo/runs/full-demo-d15/seed-1"
mesh="$repo/build/meshes/consigma1-full-4um-c2.1-4.2mm-g2.1mm"
python="$repo/.venv/bin/python"

if [ "${1:-}" = "--keep" ]; then   # the latest restart file and the outputs, compressed into docs/
  latest=$(find "$out" -maxdepth 1 -name 'restart.[0-9]*' -printf '%f\n' | sort -t. -k2 -n | tail -1)
  "$repo/cases/slurm/merge-elements.sh" "$out"   # one elements.txt: what the analysis reads
  find "$kept" -maxdepth 1 -name '*.xz' ! -name 'restart.*' -delete
  if [ -n "$latest" ]; then
    rm -f "$kept"/restart.*.xz
    xz -T2 -6 -c "$out/$latest" > "$kept/$latest.xz"
  else   # a finished run (--until) has none left: the kept one stays, its records roll back to it
    echo "no restart file in $out (a finished run): keeping $(cd "$kept" && ls restart.*.xz)"
  fi
  for f in log.lammps massflow.txt residence.txt elements.txt $(cd "$out" && ls log.upto-*.lammps); do
    xz -c "$out/$f" > "$kept/$f.xz"
  done
  cp "$out"/{feed.in,phase.in,params.json,zones.txt,machine.in,holdup.txt} "$kept"/
  echo "kept $latest and the outputs in $kept"
  exit 0
fi

ranks="${1:-2}"
until=""
if [ "${2:-}" = "--until" ]; then
  until="${3:?--until needs a time in s}"
fi
[ -f "$mesh/zones.txt" ] || "$python" -m tsg_meshes build consigma1-full "$mesh" --tolerance 4e-06 \
  --clearance 0.0021 --screw-clearance 0.0042 --disc-gap 0.0021
if [ ! -d "$out" ]; then   # unpack the kept state
  mkdir -p "$out"
  cp "$kept"/{feed.in,phase.in,params.json,zones.txt,machine.in,holdup.txt} "$out"/
  for f in "$kept"/*.xz; do xz -dc "$f" > "$out/$(basename "$f" .xz)"; done
fi
vars=$("$python" - "$out" "$mesh" "$until" <<'PY'
import json, re, sys
out, mesh, until = sys.argv[1], sys.argv[2], sys.argv[3]
given = json.load(open(f"{out}/params.json"))["variables"]
given.update({"feed_file": f"{out}/feed.in", "mesh_dir": mesh})
if until:   # the sampling window ends at T: t_sample from the in-script steady state's time
    steady = float(re.search(r"t = (\S+) s", open(f"{out}/holdup.txt").readline()).group(1))
    if not float(until) > steady:
        sys.exit(f"--until {until} is not allowed: a time in s after the steady state at {steady:.6g} s")
    given.update({"t_sample": f"{float(until) - steady:.9g}", "inside_records": "1"})
skip = {"out_dir", "procs_x", "restart_every", "case_dir"}
print(" ".join(f"-var {k} {v}" for k, v in given.items() if k not in skip))
PY
)
# segment.sh refuses a restart file the previous segment started from too (a job chain that makes no
# progress); run by hand, a segment stopped before its next restart file is simply started again
rm -f "$out/last-restart"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
launch=""
[ "$ranks" -gt 1 ] && launch="mpirun -np $ranks --oversubscribe"
TSG_OUT="$out" TSG_LAUNCH="$launch" TSG_RESTART_EVERY=80000 TSG_VARS="$vars" SLURM_NTASKS="$ranks" \
  "$repo/cases/slurm/segment.sh" full /dev/null
