#!/usr/bin/env bash
# Merge a stopped or finished segmented run's element statistics into one file, each sampled step once:
#
#   cases/slurm/merge-elements.sh RUN_DIR
#
# segment.sh keeps each earlier segment's statistics as elements.upto-<step>.txt (LIGGGHTS would
# overwrite them). A segment continues from a restart file older than the step its predecessor
# reached, so the steps in between are sampled twice; the later segment's rows win, as the mass-flow
# and residence records do (their fixes drop what was written after the restart file). The rule is
# tsg_analysis.run_files.merged_element_text, which the analysis also applies when it reads a run
# that is still going (it never replaces a file a running segment writes; this does: segment.sh
# calls it when the run is done, kept-run.sh keep after the segment was stopped).
set -euo pipefail
out="${1:?usage: merge-elements.sh RUN_DIR}"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
exec "$repo/.venv/bin/tsg-analysis" merge-elements "$out" > /dev/null
