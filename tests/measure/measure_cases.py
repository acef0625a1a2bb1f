"""Inputs and readers shared by the measurement tests (fix residence/time, compute element/stats,
fix massflow/planes).

Every LIGGGHTS input here is deterministic kinematics: 1 mm spheres on separate (y, z) lanes 2.5 mm
apart, each lane with one velocity, so no two particles ever touch and `fix nve/sphere` moves each one
at its set velocity; or a static arrangement without time integration. The answers are then known in
closed form (times = distances / speeds, volumes from spherical caps).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

RADIUS = 5e-4
DENSITY = 2500.0
MASS = DENSITY * 4.0 / 3.0 * math.pi * RADIUS**3

# 1 conveying [0.01, 0.03), 2 kneading [0.03, 0.04), gap, 3 chopping [0.05, 0.07), 4 kneading [0.07, 0.08)
ZONES = [(1, "conveying", 0.01, 0.03, 2.0e-6), (2, "kneading", 0.03, 0.04, 1.0e-6),
         (3, "chopping", 0.05, 0.07, 2.0e-6), (4, "kneading", 0.07, 0.08, 1.0e-6)]


def zones_text(zones=ZONES) -> str:
    lines = ["# test zones: index type x_start_m x_end_m free_volume_m3"]
    lines += [f"{i} {kind} {a:.17g} {b:.17g} {v:.17g}" for i, kind, a, b, v in zones]
    return "\n".join(lines) + "\n"


def lanes(n: int) -> list[tuple[float, float]]:
    """n distinct (y, z) lanes, 2.5 mm apart, inside |y|, |z| <= 7.5 mm."""
    grid = [(-0.0075 + 0.0025 * j, -0.0075 + 0.0025 * k) for j in range(7) for k in range(7)]
    assert n <= len(grid)
    return grid[:n]


@dataclass
class Mover:
    x0: float
    v: float
    y: float
    z: float


def particles_include(movers: list[Mover]) -> str:
    """create_atoms + set velocities, atom ids 1..n in order."""
    out = []
    for m in movers:
        out.append(f"create_atoms 1 single {m.x0:.17g} {m.y:.17g} {m.z:.17g} units box")
    out.append(f"set atom * diameter {2 * RADIUS:.17g} density {DENSITY:.17g}")
    out.append("velocity all set 0 0 0 units box")
    for i, m in enumerate(movers, start=1):
        out.append(f"set atom {i} vx {m.v:.17g}")
    return "\n".join(out) + "\n"


BASE = """# deterministic kinematics: particles on separate lanes, no contacts
atom_style    granular
atom_modify   map array
boundary      ${bx} f f
newton        off
communicate   single vel yes
units         si
processors    ${px} 1 1
region        box block ${xlo} ${xhi} -0.01 0.01 -0.01 0.01 units box
create_box    1 box
neighbor      0.0005 bin
neigh_modify  delay 0 every 1 check yes
fix m1 all property/global youngsModulus peratomtype 5.0e7
fix m2 all property/global poissonsRatio peratomtype 0.25
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
"""

RESTART_BASE = """atom_style    granular
atom_modify   map array
boundary      ${bx} f f
newton        off
communicate   single vel yes
units         si
processors    ${px} 1 1
read_restart  state.restart
neighbor      0.0005 bin
neigh_modify  delay 0 every 1 check yes
fix m1 all property/global youngsModulus peratomtype 5.0e7
fix m2 all property/global poissonsRatio peratomtype 0.25
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
"""


def variables(periodic: bool, px: int = 1, xlo: float = 0.0, xhi: float = 0.1) -> dict:
    return {"bx": "p" if periodic else "f", "px": px, "xlo": xlo, "xhi": xhi}


@dataclass
class Record:
    id: int
    entry: float
    exit: float
    residence: float
    reason: str
    types: np.ndarray      # conveying kneading chopping
    zones: np.ndarray


def read_records(path: Path) -> tuple[list[str], list[Record]]:
    header, records = [], []
    for line in Path(path).read_text().splitlines():
        if line.startswith("#"):
            header.append(line)
            continue
        f = line.split()
        records.append(Record(int(f[0]), float(f[1]), float(f[2]), float(f[3]), f[4],
                              np.array([float(v) for v in f[5:8]]), np.array([float(v) for v in f[8:]])))
    return header, records


def record_lines(path: Path) -> list[str]:
    return [l for l in Path(path).read_text().splitlines() if l and not l.startswith("#")]


def expected_zone_times(a: float, b: float, v: float, zones=ZONES, lo=-math.inf, hi=math.inf) -> np.ndarray:
    """Time a particle moving at |v| spends in each zone while going from x = a to x = b (a < b),
    counting only [lo, hi) (the analysis domain)."""
    out = []
    for _, _, zs, ze, _ in zones:
        s, e = max(zs, a, lo), min(ze, b, hi)
        out.append(max(0.0, e - s) / abs(v))
    return np.array(out)


def type_times(zone_times: np.ndarray, zones=ZONES) -> np.ndarray:
    order = {"conveying": 0, "kneading": 1, "chopping": 2}
    out = np.zeros(3)
    for t, (_, kind, *_rest) in zip(zone_times, zones):
        out[order[kind]] += t
    return out


def sphere_slab_volume_reference(c: float, r: float, x0: float, x1: float) -> float:
    """Independent of the C++ header: whole sphere minus the textbook caps π h² (3R - h)/3 cut off
    below x0 and above x1."""
    def cap(h: float) -> float:
        h = min(max(h, 0.0), 2 * r)
        return math.pi * h * h * (3 * r - h) / 3
    if x1 <= c - r or x0 >= c + r:
        return 0.0
    return 4 / 3 * math.pi * r**3 - cap(x0 - (c - r)) - cap((c + r) - x1)


def plane_stl(x: float) -> str:
    """ASCII STL of the square x = const, |y|, |z| <= 0.01 (two triangles), for fix mesh/surface."""
    a, b = -0.01, 0.01
    tris = [((x, a, a), (x, b, a), (x, b, b)), ((x, a, a), (x, b, b), (x, a, b))]
    out = ["solid plane"]
    for tri in tris:
        out += ["facet normal 1 0 0", " outer loop"] + [f"  vertex {p[0]!r} {p[1]!r} {p[2]!r}" for p in tri] + \
               [" endloop", "endfacet"]
    return "\n".join(out + ["endsolid plane"]) + "\n"
