#!/usr/bin/env bash
# Merge a segmented run's element statistics into one file, each sampled step once:
#
#   cases/slurm/merge-elements.sh RUN_DIR
#
# segment.sh keeps each earlier segment's statistics as elements.upto-<step>.txt (LIGGGHTS would
# overwrite them). A segment continues from a restart file older than the step its predecessor
# reached, so the steps in between are sampled twice; the later segment's rows win, as the mass-flow
# and residence records do (their fixes drop what was written after the restart file). segment.sh
# calls this when the run is done; call it by hand to analyse a run that is still going or stopped.
set -euo pipefail
out="${1:?usage: merge-elements.sh RUN_DIR}"
mapfile -t upto < <(find "$out" -maxdepth 1 -name 'elements.upto-*.txt' -printf '%f\n' | sort -t- -k2 -n | sed "s|^|$out/|")
[ "${#upto[@]}" -gt 0 ] || exit 0
parts=() firsts=()   # the files with samples, and the first sampled step of each
for f in "${upto[@]}" "$out/elements.txt"; do
  [ -f "$f" ] || continue
  first=$(awk 'FNR > 3 && NF == 2 { print $1; exit }' "$f")
  [ -n "$first" ] && parts+=("$f") && firsts+=("$first")
done
# each file keeps the steps before the next file's first step; the last keeps all
awk -v limits="${firsts[*]:1}" '
  BEGIN { n = split(limits, limit, " ") }
  FNR == 1 { file++ }
  FNR <= 3 { if (file == 1) print; next }
  NF == 2 { keep = file > n || $1 < limit[file] }
  keep' "${parts[@]}" > "$out/elements.merged"
mv "$out/elements.merged" "$out/elements.txt"
rm -f "${upto[@]}"   # their steps are in elements.txt now
