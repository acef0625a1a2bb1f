"""Machine geometry of a built mesh directory: one file, `machine.in`, read by everything.

The mesh generator writes it next to the meshes from the profile constants (profile.py, seed paper
Tables 1-2). It is a LIGGGHTS include (`variable NAME equal VALUE`, SI units), so the case
includes (domain.in, geometry.in, the screws) take the axes and the bore from it, and Python
(tests, analysis) reads the same keys with `read_machine`. Keys:

  centre_distance   distance between the screw axes, m
  bore_radius       radius of each barrel bore, m
  screw_outer_radius, screw_root_radius   screw tip and root radii, m
  barrel_clearance  gap between a flight tip and the barrel, m (paper 0.44 mm)
  screw_clearance   gap between the tip of one screw and the root of the other in an axial section, m
                    (paper 0.35 mm)
  disc_gap          axial spacer between staggered kneading discs, m (paper 0: the discs touch)
  axis1_y, axis2_y  y of the screw 1 and screw 2 axes (both along x at z = axis_z), m
  axis_z            z of both axes, m
  box_y, box_z      half extents of a simulation box that contains the barrel with 1 mm room, m
"""
from __future__ import annotations

import re
from pathlib import Path

from .profile import BORE_RADIUS, CENTRE_DISTANCE, ScrewProfile

MACHINE_FILE = "machine.in"
ROOM = 1e-3   # m between the barrel and the box faces
_LINE = re.compile(r"^variable\s+(\w+)\s+equal\s+(\S+)", re.MULTILINE)


def machine_values(profile: ScrewProfile = ScrewProfile(), disc_gap: float = 0.0) -> dict[str, float]:
    half = CENTRE_DISTANCE / 2
    return {"centre_distance": CENTRE_DISTANCE, "bore_radius": BORE_RADIUS,
            "screw_outer_radius": profile.outer_radius, "screw_root_radius": profile.root_radius,
            "barrel_clearance": BORE_RADIUS - profile.outer_radius,
            "screw_clearance": CENTRE_DISTANCE - profile.outer_radius - profile.root_radius,
            "disc_gap": disc_gap,
            "axis1_y": -half, "axis2_y": half, "axis_z": 0.0,
            "box_y": half + BORE_RADIUS + ROOM, "box_z": BORE_RADIUS + ROOM}


def machine_text(profile: ScrewProfile = ScrewProfile(), disc_gap: float = 0.0) -> str:
    lines = ["# Machine geometry written by tsg_meshes (meshes/tsg_meshes/machine.py); SI units.",
             "# Screws along +x; read by cases/include/*.in and by Python (tsg_meshes.machine.read_machine)."]
    lines += [f"variable {name} equal {value:.10g}" for name, value in machine_values(profile, disc_gap).items()]
    return "\n".join(lines) + "\n"


def read_machine(path: Path | str) -> dict[str, float]:
    """The keys of a machine.in (a file, or a directory holding one)."""
    path = Path(path)
    if path.is_dir():
        path = path / MACHINE_FILE
    values = {name: float(value) for name, value in _LINE.findall(path.read_text())}
    missing = set(machine_values()) - set(values)
    if missing:
        raise ValueError(f"{path}: lacks {', '.join(sorted(missing))} (rebuild the meshes: ./tsg setup)")
    return values


def machine_file_complete(path: Path | str) -> bool:
    """Whether a directory (or file) has a machine.in with every key of this version (an older
    build lacks the clearances: rebuild it)."""
    try:
        read_machine(path)
    except (OSError, ValueError):
        return False
    return True
