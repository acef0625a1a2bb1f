#!/usr/bin/env bash
# The squeeze treatment on the paper machine at 400 um (docs/stability.md, "Squeezes on the paper
# machine"): from the faithful run's restart at step 380000 (t = 0.1892 s) over the window of the
# faithful run's next segment (to step 420000, t = 0.2091 s), the case file's defaults plus
# yield_pressure_pg 2.5e6 (p_y = 2.5 MPa: yields at 1 % of R); the wall contacts of the restart file
# (written with Hertz) start afresh (reset_contacts 1). Measured at commit 0c19b83 (build/lmp then), 1 rank:
# it stopped with 3 lost particles before step 410000; its log.lammps and squeezes.txt are kept here.
# Needs runs/paper-400um-faithful/restart.380000 (scripts/kept-run.sh run studies/paper-400um/faithful
# reaches it from the fill; the kept restart is a later one).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
faithful="$repo/runs/paper-400um-faithful"
out="$repo/runs/paper-400um-yield"
mkdir -p "$out" && cp "$faithful/fill.vars" "$faithful/zones.txt" "$out/" && cd "$out"
"${TSG_LMP:-$repo/build/lmp}" -in "$repo/cases/in.tsg_periodic" -echo none -var case_dir "$repo/cases" -var out_dir "$out" \
  -var procs_x 1 -var start restart -var restart_file "$faithful/restart.380000" -var d_mean 0.0004 \
  -var thermo_every 10000 -var stats_every 10000 -var t_startup 0.20913 -var t_sample 1e-6 \
  -var fill_file "$faithful/fill.in" -var mesh_dir "$repo/build/meshes/consigma1-periodic-1um" \
  -var domain_length 0.095833333333 -var yield_pressure_pg 2.5e6 -var reset_contacts 1
