#!/usr/bin/env bash
# One job segment of a case run that is longer than a job may last (cases/slurm/*.slurm; docs/cluster.md).
#
#   segment.sh CASE JOB_SCRIPT
#
# 1. If ${out}/DONE exists, the run is finished: exit. If ${out}/FAILED exists, stop the chain.
# 2. Submit the successor first (sbatch --dependency=afterany:$SLURM_JOB_ID JOB_SCRIPT; a task of a job
#    array with --array=$SLURM_ARRAY_TASK_ID): it starts when this segment ends, however it ends (also
#    killed at the time limit), so the chain needs no signal handling.
# 3. Continue from the newest complete restart file (one whose step the log shows a later thermo row
#    for; a file being written when the job was killed is skipped), or start from the beginning (the
#    periodic case's fill, the full case's empty barrel). The measurement fixes drop the records
#    the killed segment wrote after that restart file (written again by the continued run).
#    The previous segment's log and element statistics are kept as log.upto-<step>.lammps and
#    elements.upto-<step>.txt (LIGGGHTS would overwrite them); residence and mass-flow records
#    continue in their files (the fixes append after a restart).
#    A run with its own machine, particles or hold-up (TSG_PREPARE) is prepared once, by the first
#    segment: tsg-run-case CASE $TSG_PREPARE --out $out --prepare-only makes its meshes and fill and
#    writes the lmp variables to ${out}/lmp.vars. Every segment passes ${out}/lmp.vars to lmp when it
#    exists (after its own variables and TSG_VARS: lmp keeps the first value of a variable given twice).
# 4. After lmp: TSG-DONE in the log -> DONE, the element statistics of all segments merged into
#    elements.txt (merge-elements.sh: where segments overlap, the later one's rows), older restart files removed; an ERROR -> FAILED (the successor exits at once);
#    the same restart file chosen twice in a row -> FAILED (no progress within one job).
# 5. Before and after lmp, restart files older than the newest TSG_KEEP_RESTARTS complete ones are
#    removed (prune-restarts.sh; default 2; 0 keeps every one): a 1.5 s run at 400 um writes about
#    150 files of 66 MB.
#
# Environment: TSG_OUT (default runs/<case>-cluster), TSG_LMP (default build/lmp), TSG_LAUNCH (the MPI
# launcher, default "srun"; "" runs lmp directly), TSG_RESTART_EVERY (steps, default 20000),
# TSG_VARS (more -var NAME VALUE for lmp), TSG_WALL_OVERLAP (guard_max_wall_overlap, if set),
# TSG_PREPARE (tsg-run-case options after the case name, e.g. "--scale paper --clearances 0.0006 0.0012
# 0.0006"; not --out), TSG_RUN_CASE (default .venv/bin/tsg-run-case), TSG_SBATCH (default sbatch),
# TSG_KEEP_RESTARTS (complete restart files kept, default 2; 0 keeps all).
set -euo pipefail
case_name="$1"
job_script="$2"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
out="${TSG_OUT:-$repo/runs/$case_name-cluster}"
lmp="${TSG_LMP:-$repo/build/lmp}"
launch="${TSG_LAUNCH-srun}"
restart_every="${TSG_RESTART_EVERY:-20000}"
ranks="${SLURM_NTASKS:-1}"
keep_restarts="${TSG_KEEP_RESTARTS:-2}"
say() { printf '[segment %s] %s\n' "${SLURM_JOB_ID:-local}" "$*"; }

case "$keep_restarts" in
  '' | *[!0-9]*) say "TSG_KEEP_RESTARTS = \"$keep_restarts\" is not allowed: a whole number of restart files (0 keeps all)"; exit 2 ;;
esac

mkdir -p "$out"
if [ -f "$out/DONE" ]; then say "$out is done: nothing to run"; exit 0; fi
if [ -f "$out/FAILED" ]; then say "$out failed before: $(cat "$out/FAILED"); remove FAILED to try again"; exit 1; fi
[ -x "$lmp" ] || { say "lmp not found: $lmp (./tsg setup builds it; or set TSG_LMP)"; exit 2; }

if [ -n "${SLURM_JOB_ID:-}" ]; then
  # a task of a job array (tsg-sweep's paper-scale runs) continues as the same index
  array=()
  [ -n "${SLURM_ARRAY_TASK_ID:-}" ] && array=(--array="$SLURM_ARRAY_TASK_ID")
  successor=$("${TSG_SBATCH:-sbatch}" --parsable ${array[@]+"${array[@]}"} --dependency="afterany:$SLURM_JOB_ID" "$job_script")
  say "successor submitted: job ${successor%%;*}"
fi

# a run with its own machine, particles or hold-up: prepared once (a segment killed while preparing
# leaves no lmp.vars, so the next one prepares again)
if [ -n "${TSG_PREPARE:-}" ] && [ ! -f "$out/lmp.vars" ]; then
  say "preparing: tsg-run-case $case_name $TSG_PREPARE --out $out --prepare-only"
  # shellcheck disable=SC2086  # TSG_RUN_CASE and TSG_PREPARE are word lists
  if ! ${TSG_RUN_CASE:-$repo/.venv/bin/tsg-run-case} "$case_name" $TSG_PREPARE --out "$out" --prepare-only; then
    echo "preparation failed: tsg-run-case $case_name $TSG_PREPARE --out $out --prepare-only" > "$out/FAILED"
    say "$(cat "$out/FAILED")"; exit 1
  fi
  printf '%s\n' "$TSG_PREPARE" > "$out/prepared-with"
elif [ -n "${TSG_PREPARE:-}" ] && [ -f "$out/prepared-with" ] && [ "$(cat "$out/prepared-with")" != "$TSG_PREPARE" ]; then
  # a chain continues the run it prepared: other options would silently not apply
  echo "TSG_PREPARE = \"$TSG_PREPARE\" is not allowed here: $out was prepared with \"$(cat "$out/prepared-with")\" (use another TSG_OUT for other options)" > "$out/FAILED"
  say "$(cat "$out/FAILED")"; exit 1
fi
prepared=()
if [ -f "$out/lmp.vars" ]; then
  while read -r name value; do prepared+=(-var "$name" "$value"); done < "$out/lmp.vars"
  say "with the $((${#prepared[@]} / 3)) variables of $out/lmp.vars"
fi

last_step=0
if [ -f "$out/log.lammps" ]; then
  last_step=$(awk 'NF >= 10 && $1 ~ /^[0-9]+$/ && $2 ~ /^[0-9.eE+-]+$/ { s = $1 } END { print s + 0 }' "$out/log.lammps")
fi
restart=$("$repo/cases/slurm/newest-restart.sh" "$out")

vars=(-var out_dir "$out" -var procs_x "$ranks" -var restart_every "$restart_every")
# the wall-overlap guard for a machine that squeezes its particles (the job scripts set it; docs/cluster.md)
[ -n "${TSG_WALL_OVERLAP:-}" ] && vars+=(-var guard_max_wall_overlap "$TSG_WALL_OVERLAP")
if [ -n "$restart" ]; then
  step="${restart##*.}"
  if [ -f "$out/last-restart" ] && [ "$(cat "$out/last-restart")" = "$step" ]; then
    echo "no progress: restart.$step was chosen by the previous segment too (raise --time or lower TSG_RESTART_EVERY)" > "$out/FAILED"
    say "$(cat "$out/FAILED")"; exit 1
  fi
  echo "$step" > "$out/last-restart"
  "$repo/cases/slurm/prune-restarts.sh" "$out" "$keep_restarts"
  mv "$out/log.lammps" "$out/log.upto-$last_step.lammps"
  [ -f "$out/elements.txt" ] && mv "$out/elements.txt" "$out/elements.upto-$last_step.txt"
  vars+=(-var start restart -var restart_file "$out/restart.$step")
  say "continuing from restart.$step (the previous segment reached step $last_step)"
else
  say "starting from the beginning (the fill, or the empty barrel of the full case)"
fi

# shellcheck disable=SC2086  # TSG_LAUNCH and TSG_VARS are word lists
# run in ${out}: LIGGGHTS writes its start-up log.liggghts, and on SIGTERM (SLURM's time limit) a
# restart_forced_liggghts_<step>.data, into the working folder
(cd "$out" && $launch "$lmp" -in "$repo/cases/in.tsg_$case_name" -echo none -var case_dir "$repo/cases" \
  "${vars[@]}" ${TSG_VARS:-} ${prepared[@]+"${prepared[@]}"}) || true

if grep -q '^TSG-DONE' "$out/log.lammps" 2>/dev/null; then
  "$repo/cases/slurm/merge-elements.sh" "$out"   # one elements.txt, each sampled step once
  find "$out" -maxdepth 1 -name 'restart.*' -delete
  touch "$out/DONE"
  say "run finished: $out (the successor finds DONE and exits)"
elif grep -q '^ERROR' "$out/log.lammps" 2>/dev/null; then
  grep -m1 '^ERROR' "$out/log.lammps" > "$out/FAILED"
  say "lmp stopped with an error: $(cat "$out/FAILED")"
  exit 1
else
  "$repo/cases/slurm/prune-restarts.sh" "$out" "$keep_restarts"
  say "segment ended before the run did: the successor continues"
fi
