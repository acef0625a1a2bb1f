#!/usr/bin/env bash
# The stability map (docs/stability.md, "Stability map") as measured: every case on one core, one run at
# a time, niced beside other work. Code: benchmarks/stability_map.py at commit d8eaa74 (the runs; the
# tables and figure are rebuilt by --merge with the code of the commit that adds this file, which reads
# the same runs); lmp: build/lmp of commit 12aa483. Window 0.05 s (180 degrees of the disc at 600 rpm),
# ladder 0.05 ... 3.2, halved down to 0.0125 when 0.05 fails, 3 bisections. Measured cost: 13 min for
# the two maps (a 1 mm run 40-80 us per step, the 400 um one 0.5 ms per step), 12 min for the repeats
# (code of commit e52a397, which adds --seed; seed 1 is the fill of the maps).
# Writes the runs under $work (their logs, squeezes.txt and inputs), the merged JSON and tables here,
# the figure to docs/img/stability_map.png.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
work="${1:-$(mktemp -d)}"
export TSG_LMP="${TSG_LMP:-$repo/build/lmp}"
export PYTHONPATH="$repo/tests:$repo/analysis:$repo/meshes:$repo/cases"
map() { nice -n 10 "$repo/.venv/bin/python" "$repo/benchmarks/stability_map.py" \
  --fractions 0.05,0.1,0.2,0.4,0.8,1.6,3.2 --bisections 3 --floor 0.0125 --window 0.05 --np 1 "$@"; }
cd "$repo"
# the tip clearances (issue 33 item 4)
map --cases gap-1.2,gap-0.8,gap-0.5,gap-0.29,paper-400um --out "$work/B"
# the extreme cases (issue 14 item 1), at the ConsiGma-1 clearance 0.44 mm
map --cases base,stiff,soft,lambda-0.99,cohesion-x10,elastic-0.99,friction-1.0,rpm-1200,coarse-1.5mm,holdup-x2,size-ratio-3 \
  --out "$work/A"
.venv/bin/python benchmarks/stability_map.py --merge "$work/A/stability_map.json" "$work/B/stability_map.json" \
  --out studies/stability-map
mv studies/stability-map/stability_map.png docs/img/stability_map.png
# the same ladder for base and the clearance cases from two other fills (the jitter's seed)
for seed in 2 3; do
  map --cases base,gap-1.2,gap-0.8,gap-0.5,gap-0.29,paper-400um --seed "$seed" --out "$work/seed-$seed"
  mkdir -p "studies/stability-map/seed-$seed"
  cp "$work/seed-$seed/stability_map.json" "$work/seed-$seed/stability_map.md" "studies/stability-map/seed-$seed/"
done
