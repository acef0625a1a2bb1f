#!/usr/bin/env bash
# A study run longer than a session: it runs in segments (cases/slurm/segment.sh, prepared once from
# tsg-run-case options) and is kept in the repository between sessions as its newest restart file and
# its outputs, compressed (docs/validation.md, "Periodic against full at 1 mm").
#
#   scripts/kept-run.sh run KEPT [RANKS] [--until T]   # start, or continue, the run KEPT/run.conf names
#   scripts/kept-run.sh keep KEPT                      # after stopping it: its newest restart file and
#                                                      # outputs, compressed into KEPT; once it is finished
#                                                      # (DONE), its outputs only
#
# KEPT/run.conf (shell variables): CASE (periodic | full | nonperiodic), OUT (the run folder; relative
# to the repository unless absolute), PREPARE (tsg-run-case options after the case name, not --out; its
# paths relative to the repository: the segments run from there), RESTART_EVERY
# (steps between restart files).
# On a fresh checkout `run` unpacks KEPT into OUT; the first segment prepares the run again (meshes,
# feed regions: the same for the same options) and continues from the kept restart file. The records
# written after that restart file by the stopped segment are dropped by the measurement fixes. A kept
# finished run (KEPT/DONE) is only unpacked: its outputs, zones and parameters are what the analysis reads.
# --until T: the sampling ends at t = T s (full case), with a residence record "inside" for every
# particle still in the granulator (the RTDs need them).
# Stop a running segment with kill (its PID, or pkill -f "in.tsg_$CASE") before `keep`.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
usage="usage: kept-run.sh run KEPT [RANKS] [--until T] | kept-run.sh keep KEPT"
action="${1:?$usage}"
kept="$(cd "${2:?$usage}" && pwd)"
[ -f "$kept/run.conf" ] || { echo "kept-run.sh: $kept/run.conf not found (CASE, OUT, PREPARE, RESTART_EVERY)" >&2; exit 2; }
# shellcheck source=/dev/null
. "$kept/run.conf"
case "${OUT:?run.conf: OUT not set}" in /*) out="$OUT" ;; *) out="$repo/$OUT" ;; esac
cd "$repo"   # PREPARE's paths (e.g. --from-state) are relative to the repository, wherever this is called from
# what a continuation reads, and what the analysis of a finished run reads (zones, parameters)
outputs=(log.lammps massflow.txt residence.txt elements.txt holdup.txt squeezes.txt phase.in fill.vars zones.txt params.json)

if [ "$action" = keep ]; then
  if pgrep -f "in.tsg_${CASE} .*$out" > /dev/null; then
    echo "kept-run.sh: a segment of $out is still running: stop it first" >&2; exit 2
  fi
  if [ -f "$out/DONE" ]; then   # finished: its outputs are the study's results, no restart file is kept
    latest=""
  else                          # the restart file a continuation starts from
    restart=$("$repo/cases/slurm/newest-restart.sh" "$out")
    [ -n "$restart" ] || { echo "kept-run.sh: no complete restart file in $out (and no DONE: not finished)" >&2; exit 2; }
    latest=$(basename "$restart")
  fi
  "$repo/cases/slurm/merge-elements.sh" "$out"      # one elements.txt: what the analysis reads
  find "$kept" -maxdepth 1 \( -name '*.xz' -o -name DONE \) -delete
  for f in "${outputs[@]}" $(cd "$out" && ls log.upto-*.lammps 2>/dev/null); do
    [ -f "$out/$f" ] && xz -T2 -c "$out/$f" > "$kept/$f.xz"
  done
  if [ -n "$latest" ]; then
    xz -T2 -6 -c "$restart" > "$kept/$latest.xz"
    echo "kept $latest and the outputs of $out in $kept ($(du -sh "$kept" | cut -f1))"
  else
    touch "$kept/DONE"
    echo "kept the outputs of the finished run $out in $kept ($(du -sh "$kept" | cut -f1)); \`run' unpacks them"
  fi
  exit 0
fi
[ "$action" = run ] || { echo "$usage" >&2; exit 2; }

ranks="${3:-2}"
until_vars=""
if [ "${4:-}" = "--until" ]; then
  until="${5:?--until needs a time in s}"
  steady=$(sed -n 's/.*t = \([0-9.eE+-]*\) s.*/\1/p' "$out/holdup.txt" 2>/dev/null | head -1)
  [ -n "$steady" ] || { echo "kept-run.sh: --until $until needs the run's steady state ($out/holdup.txt)" >&2; exit 2; }
  awk -v t="$until" -v s="$steady" 'BEGIN { exit !(t > s) }' || {
    echo "--until $until is not allowed: a time in s after the steady state at $steady s" >&2; exit 2; }
  until_vars="-var t_sample $(awk -v t="$until" -v s="$steady" 'BEGIN { printf "%.9g", t - s }') -var inside_records 1"
fi
if [ ! -d "$out" ]; then   # a fresh checkout: the kept state
  mkdir -p "$out"
  for f in "$kept"/*.xz; do [ -f "$f" ] && xz -dc "$f" > "$out/$(basename "$f" .xz)"; done
  if [ -f "$kept/DONE" ]; then
    touch "$out/DONE"
    if [ ! -f "$out/zones.txt" ] || [ ! -f "$out/params.json" ]; then
      # kept before its zones and parameters were kept: its preparation makes them (the same for the same options)
      ${TSG_RUN_CASE:-$repo/.venv/bin/tsg-run-case} "$CASE" $PREPARE --out "$out" --prepare-only > /dev/null \
        || { echo "kept-run.sh: preparing $out for its analysis failed: tsg-run-case $CASE $PREPARE --out $out --prepare-only" >&2; exit 1; }
    fi
    echo "kept-run.sh: $OUT is a finished run: its outputs are unpacked into $out, nothing to run"; exit 0
  fi
fi
# run by hand, a segment stopped before its next restart file is simply started again
rm -f "$out/last-restart"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
launch=""
[ "$ranks" -gt 1 ] && launch="mpirun -np $ranks --oversubscribe"
TSG_OUT="$out" TSG_LAUNCH="$launch" TSG_RESTART_EVERY="${RESTART_EVERY:?run.conf: RESTART_EVERY not set}" \
  TSG_PREPARE="${PREPARE:?run.conf: PREPARE not set}" TSG_VARS="$until_vars" SLURM_NTASKS="$ranks" \
  "$repo/cases/slurm/segment.sh" "$CASE" /dev/null
