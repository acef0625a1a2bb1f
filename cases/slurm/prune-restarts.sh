#!/usr/bin/env bash
# Removes the restart files of a run folder that no continuation needs: every restart.<step> older
# than its newest KEEP complete ones (complete: the log shows a later thermo row, newest-restart.sh).
# Files newer than the newest complete one (being written, or not yet followed by a thermo row) are
# never touched. Prints what it removed; KEEP 0 removes nothing (every restart file kept, e.g. to
# branch studies from intermediate states: python -m tsg_cases.states keep).
#
#   cases/slurm/prune-restarts.sh RUN_DIR KEEP
set -euo pipefail
usage="usage: prune-restarts.sh RUN_DIR KEEP"
out="${1:?$usage}"
keep="${2:?$usage}"
case "$keep" in
  '' | *[!0-9]*) echo "prune-restarts.sh: KEEP = \"$keep\" is not allowed: a whole number of restart files (0 keeps all)" >&2; exit 2 ;;
esac
[ "$keep" -eq 0 ] && exit 0
newest=$("$(dirname "${BASH_SOURCE[0]}")/newest-restart.sh" "$out")
[ -n "$newest" ] || exit 0
newest_step="${newest##*.}"
complete=0
for step in $(find "$out" -maxdepth 1 -name 'restart.*' -printf '%f\n' | sed 's/^restart\.//' | grep -E '^[0-9]+$' | sort -n -r); do
  [ "$step" -gt "$newest_step" ] && continue
  complete=$((complete + 1))
  [ "$complete" -le "$keep" ] && continue
  rm -f "$out/restart.$step"
  echo "removed $out/restart.$step (older than the newest $keep complete restart files)"
done
