"""Where the particles that hardly move along the axis sit, from two particle dumps of a periodic run.

    .venv/bin/python studies/validation/slow-particles.py RUN_DIR [--first STEP] [--last STEP] [--slow-mm 5]

Reads RUN_DIR/dumps/particles_<step>.vtk at the two steps (default: the last two dumps) and the
machine (RUN_DIR/machine.in) and zones (RUN_DIR/zones.txt). A particle is slow when its axial
displacement between the dumps (periodic images resolved by the smallest |Δx| modulo the domain
length) is under --slow-mm. Printed per zone: particles, slow ones, and the share of each that lies
in the flight-tip layer, whose centre is farther from the nearer screw axis than the screw's outer
radius (between the flight tips and the barrel), and the share out of the flights' reach, whose
whole sphere lies beyond the outer radius, so that no flight flank can touch it (only a particle
smaller than the tip clearance can be there). A last line gives where those lie (the share in the
lower half of the barrel; gravity is along -z) and how fast they go round the nearer axis against
the others, at the second dump. Written for docs/validation.md
("the stagnant layer"); the particles of one dump are matched to the other's by id.
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import numpy as np

from tsg_analysis.dumps import find_dump_files, read_vtk_dump, step_from_name
from tsg_analysis.run import Run


def machine_value(text: str, name: str) -> float:
    found = re.search(rf"variable {name} equal (\S+)", text)
    if found is None:
        raise SystemExit(f"machine.in has no {name}")
    return float(found.group(1))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("--first", type=int, help="step of the first dump (default: the last but one)")
    parser.add_argument("--last", type=int, help="step of the second dump (default: the last)")
    parser.add_argument("--slow-mm", type=float, default=5.0, help="axial displacement under which a particle is slow")
    args = parser.parse_args(argv)
    paths, _ = find_dump_files(args.run_dir)
    by_step = {step_from_name(p): p for p in paths if p.name.startswith("particles_")}
    steps = sorted(by_step)
    if len(steps) < 2:
        raise SystemExit(f"{args.run_dir}: fewer than two particle dumps")
    first = args.first if args.first is not None else steps[-2]
    last = args.last if args.last is not None else steps[-1]
    a, b = read_vtk_dump(by_step[first]), read_vtk_dump(by_step[last])
    machine = (args.run_dir / "machine.in").read_text()
    zones = Run(args.run_dir).zones
    length = float(zones.x_end[-1] - zones.x_start[0])
    outer = machine_value(machine, "screw_outer_radius")
    axes = [(machine_value(machine, f"axis{k}_y"), machine_value(machine, "axis_z")) for k in (1, 2)]

    order_a, order_b = np.argsort(a.columns["id"]), np.argsort(b.columns["id"])
    ids = a.columns["id"][order_a]
    if not np.array_equal(ids, b.columns["id"][order_b]):
        raise SystemExit("the two dumps hold different particles")
    xa, xb = a.columns["x"][order_a], b.columns["x"][order_b]
    shift = np.remainder(xb - xa + length / 2, length) - length / 2   # the smallest periodic displacement
    y, z = b.columns["y"][order_b], b.columns["z"][order_b]
    distances = np.array([np.hypot(y - ay, z - az) for ay, az in axes])
    nearest = distances.min(axis=0)
    # the motion round the nearer axis (m/s) and the side of the barrel (gravity is along -z)
    axis_y = np.array([ay for ay, _ in axes])[distances.argmin(axis=0)]
    below = z - axes[0][1] < 0
    round_speed = np.abs((y - axis_y) * b.columns["vz"][order_b] - (z - axes[0][1]) * b.columns["vy"][order_b]) / nearest
    in_tip_layer = nearest > outer
    out_of_reach = nearest - b.columns["radius"][order_b] > outer
    slow = np.abs(shift) < args.slow_mm * 1e-3
    zone = np.searchsorted(zones.x_end, np.remainder(xb - zones.x_start[0], length) + zones.x_start[0], side="right")
    print(f"{args.run_dir}: dumps at steps {first} and {last}; {len(ids)} particles; slow: |Δx| < {args.slow_mm} mm; "
          f"tip layer: farther than {outer * 1e3:.2f} mm from the nearer screw axis")
    print("| zone | particles | in the tip layer | out of the flights' reach | slow | slow and in the tip layer | "
          "slow and out of reach |")
    print("|---|---|---|---|---|---|---|")

    def share(mask: np.ndarray, within: np.ndarray) -> str:
        return f"{mask[within].mean():.0%}" if within.any() else "-"
    for k, label in enumerate([*zones.labels, "all"]):
        here = zone == k if label != "all" else np.ones(len(ids), bool)
        print(f"| {label} | {here.sum()} | {share(in_tip_layer, here)} | {share(out_of_reach, here)} | "
              f"{(here & slow).sum()} | {share(in_tip_layer, here & slow)} | {share(out_of_reach, here & slow)} |")
    reach = out_of_reach
    print(f"out of the flights' reach: {reach.sum()} particles, {below[reach].mean() if reach.any() else float('nan'):.0%} "
          f"of them in the lower half of the barrel; mean speed round the nearer axis "
          f"{round_speed[reach].mean() if reach.any() else float('nan'):.3f} m/s (the others "
          f"{round_speed[~reach].mean() if (~reach).any() else float('nan'):.3f} m/s), at step {last}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
