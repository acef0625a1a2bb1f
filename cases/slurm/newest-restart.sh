#!/usr/bin/env bash
# The newest complete restart file of a run folder: one whose step the log shows a later thermo row
# for (a file being written when the run was killed is skipped). Prints its path, or nothing.
#
#   cases/slurm/newest-restart.sh RUN_DIR
set -euo pipefail
out="${1:?usage: newest-restart.sh RUN_DIR}"
last_step=0
if [ -f "$out/log.lammps" ]; then
  last_step=$(awk 'NF >= 10 && $1 ~ /^[0-9]+$/ && $2 ~ /^[0-9.eE+-]+$/ { s = $1 } END { print s + 0 }' "$out/log.lammps")
fi
for step in $(find "$out" -maxdepth 1 -name 'restart.*' -printf '%f\n' | sed 's/^restart\.//' | grep -E '^[0-9]+$' | sort -n -r); do
  if [ "$step" -lt "$last_step" ]; then echo "$out/restart.$step"; exit 0; fi
done
