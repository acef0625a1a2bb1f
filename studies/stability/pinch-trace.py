"""Time series of chosen particles from LAMMPS text dumps (`dump custom` with id type x y z vx vy vz
fx fy fz omegax omegay omegaz radius), for tracing a squeeze release (docs/stability.md).

    .venv/bin/python studies/stability/pinch-trace.py 'DUMP_GLOB' ID [ID ...] --dt SECONDS --machine RUN_DIR/machine.in \
        --length L > trace.csv

One CSV row per dump and particle: step, time from the first dump (s), speed (m/s), spin (rad/s),
force (N), the distance of its centre from the nearer screw axis (m), its radius (m), and every
particle it overlaps then (id:overlap/own radius; the x direction periodic with length L).
"""
from __future__ import annotations

import argparse
import glob
import re
import sys

import numpy as np


def read_dump(path: str) -> tuple[int, dict[str, np.ndarray]]:
    with open(path) as handle:
        lines = handle.readlines()
    step = int(lines[lines.index("ITEM: TIMESTEP\n") + 1])
    header = next(i for i, line in enumerate(lines) if line.startswith("ITEM: ATOMS"))
    names = lines[header].split()[2:]
    data = np.loadtxt(lines[header + 1:], ndmin=2)
    return step, {name: data[:, k] for k, name in enumerate(names)}


def machine_value(text: str, name: str) -> float:
    found = re.search(rf"variable {name} equal (\S+)", text)
    if found is None:
        raise SystemExit(f"machine file has no {name}")
    return float(found.group(1))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("dumps", help="glob of the dump files (quoted)")
    parser.add_argument("ids", type=int, nargs="+")
    parser.add_argument("--dt", type=float, required=True, help="time step of the dumped steps, s")
    parser.add_argument("--machine", required=True, help="the run's machine.in (screw axes)")
    parser.add_argument("--length", type=float, required=True, help="periodic length along x, m")
    args = parser.parse_args(argv)
    files = sorted(glob.glob(args.dumps), key=lambda name: int(re.findall(r"(\d+)", name)[-1]))
    if not files:
        raise SystemExit(f"no dump matches {args.dumps}")
    machine = open(args.machine).read()
    axes = [(machine_value(machine, f"axis{k}_y"), machine_value(machine, "axis_z")) for k in (1, 2)]
    print("step,time_s,id,speed_m_s,spin_rad_s,force_N,axis_distance_m,radius_m,overlaps")
    first = None
    for path in files:
        step, atoms = read_dump(path)
        first = step if first is None else first
        centres = np.column_stack([atoms["x"], atoms["y"], atoms["z"]])
        for wanted in args.ids:
            k = int(np.flatnonzero(atoms["id"] == wanted)[0])
            gap = centres - centres[k]
            gap[:, 0] -= args.length * np.round(gap[:, 0] / args.length)
            overlap = atoms["radius"] + atoms["radius"][k] - np.linalg.norm(gap, axis=1)
            touching = [j for j in np.flatnonzero(overlap > 0) if j != k]
            cells = " ".join(f"{int(atoms['id'][j])}:{overlap[j] / atoms['radius'][k]:.3f}" for j in touching)
            speed = np.linalg.norm([atoms[c][k] for c in ("vx", "vy", "vz")])
            spin = np.linalg.norm([atoms[c][k] for c in ("omegax", "omegay", "omegaz")])
            force = np.linalg.norm([atoms[c][k] for c in ("fx", "fy", "fz")])
            distance = min(np.hypot(atoms["y"][k] - ay, atoms["z"][k] - az) for ay, az in axes)
            print(f"{step},{(step - first) * args.dt:.6e},{wanted},{speed:.4f},{spin:.1f},{force:.4e},{distance:.6e},"
                  f"{atoms['radius'][k]:.6e},{cells}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
