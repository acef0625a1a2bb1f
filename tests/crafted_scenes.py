"""The crafted scenes of the LIGGGHTS-level guard and squeeze tests (tests/cases/test_guards.py,
tests/measure/test_lmp_squeeze_ledger.py, tests/errors/table_guards.py): one particle material, a box
of 2 cm around the origin, meshes written as ASCII STL, and the guards that stop a run on rank 1
only (`processors 2 1 1`: rank 1 holds x > 0)."""
from __future__ import annotations

import math

RADIUS = 0.001      # m
DENSITY = 2500.0    # kg/m^3
YOUNGS, POISSON = 5.0e7, 0.25
SHEAR = YOUNGS / (2 * (1 + POISSON))
# Rayleigh time (Li, Xu & Thornton 2005), the estimate check/contact must print
RAYLEIGH = math.pi * RADIUS * math.sqrt(DENSITY / SHEAR) / (0.1631 * POISSON + 0.8766)
TIMESTEP = 1e-6


# the particle material and contact model (elastic: restitution 1), also after a read_restart
MATERIAL = """neighbor      0.0005 bin
neigh_modify  delay 0
fix m1 all property/global youngsModulus peratomtype 5.0e7
fix m2 all property/global poissonsRatio peratomtype 0.25
fix m3 all property/global coefficientRestitution peratomtypepair 1 1.0
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
"""


def setup(processors: str | None = None, boundary: str = "f f f") -> str:
    """Atom style, boundaries and the 2 cm box region, before create_box or read_restart."""
    grid = f"processors    {processors}\n" if processors else ""
    return f"""atom_style    granular
atom_modify   map array
boundary      {boundary}
newton        off
communicate   single vel yes
{grid}units         si
region        box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box
"""


def header(processors: str | None = None, boundary: str = "f f f") -> str:
    """Granular Hertz particles in the box (elastic: restitution 1)."""
    return setup(processors, boundary) + "create_box    1 box\n" + MATERIAL


HEADER = header()


def stl(name: str, triangles: list[tuple[tuple[float, float, float], ...]]) -> str:
    facets = "".join("facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x!r} {y!r} {z!r}\n" for x, y, z in t)
                     + "endloop\nendfacet\n" for t in triangles)
    return f"solid {name}\n{facets}endsolid {name}\n"


# the plane z = 0, 1 cm square
PLANE = stl("plane", [((-0.005, -0.005, 0.0), (0.005, -0.005, 0.0), (0.005, 0.005, 0.0)),
                      ((-0.005, -0.005, 0.0), (0.005, 0.005, 0.0), (-0.005, 0.005, 0.0))])
# a small disc far below that turns about x (a wall/gran/corotating fix needs one turning mesh)
LOW_DISC = stl("disc", [((-0.008, -0.001, -0.009), (-0.008, 0.001, -0.009), (-0.008, 0.001, -0.007)),
                        ((-0.008, -0.001, -0.009), (-0.008, 0.001, -0.007), (-0.008, -0.001, -0.007))])
# The wedge: two planes through the x axis, each at ALPHA from the vertical, their normals (vertex
# order) facing the particle above the apex. A centre at height z is z sin(ALPHA) from each.
ALPHA = math.radians(30.0)
_S, _C, _L = math.sin(ALPHA), math.cos(ALPHA), 0.006
WEDGE_A = stl("wall_a", [((-_L, 0.0, 0.0), (_L, 0.0, 0.0), (_L, _L * _S, _L * _C)),
                         ((-_L, 0.0, 0.0), (_L, _L * _S, _L * _C), (-_L, _L * _S, _L * _C))])
WEDGE_B = stl("wall_b", [((-_L, 0.0, 0.0), (_L, -_L * _S, _L * _C), (_L, 0.0, 0.0)),
                         ((-_L, 0.0, 0.0), (-_L, -_L * _S, _L * _C), (_L, -_L * _S, _L * _C))])


def corotating_walls(fixed: list[str], extra: str = "") -> str:
    """The meshes `fixed` (files <name>.stl) held by a fix wall/gran/corotating `walls`, with the
    turning LOW_DISC (disc.stl)."""
    meshes = "".join(f"fix {name} all mesh/surface file {name}.stl type 1\n" for name in fixed + ["disc"])
    return meshes + (f"fix walls all wall/gran/corotating model hertz tangential history mesh n_meshes {len(fixed) + 1} "
                     f"meshes {' '.join(fixed)} disc " + " ".join(f"fixed {name}" for name in fixed) +
                     " corotate disc origin 0 0 -0.008 axis 1 0 0 period 1" + (f" {extra}" if extra else "") + "\n")


# ---- a guard that fires on rank 1 only -------------------------------------------------------------
# Two particles, one at rest on rank 0 (x < 0), one on rank 1 (x > 0) that trips the guard; the log
# is named by a `log` command, as the cases do (cases/include/output_dir.in). Each scene: the input,
# its files, and the words its message must hold in log.lammps (what happened, to which particle,
# where), whichever rank found it.
RANK_ONE_HEADER = "log log.lammps\n" + header("2 1 1", boundary="p f f")  # periodic along x, as the cases


def _two_particles(mover: tuple[float, float, float]) -> str:
    x, y, z = mover
    return f"""create_atoms 1 single -0.003 -0.002 0.005 units box
create_atoms 1 single {x!r} {y!r} {z!r} units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
group mover id 2
timestep {TIMESTEP!r}
"""


RANK_ONE_GUARDS: dict[str, tuple[str, dict[str, str], tuple[str, ...]]] = {
    # fix check/contact's motion guard (every step)
    "max_speed": (RANK_ONE_HEADER + _two_particles((0.003, 0.0, 0.0)) + """velocity mover set 3 0 0 units box
fix integrate all nve/sphere
fix check all check/contact every 10 max_speed 2
run 100
""", {}, ("check/contact: step 0: particle 2 moves at 3 m/s, above max_speed = 2 m/s",)),
    # fix check/contact's wall-overlap guard, a mesh of fix wall/gran/corotating (tsg::WallContactSource)
    "max_wall_overlap": (RANK_ONE_HEADER + corotating_walls(["plane"]) +
                         _two_particles((0.003, 0.0002, 1.01 * RADIUS)) + """fix push mover move linear 0 0 -0.1
fix check all check/contact every 10 walls walls max_wall_overlap 0.3
run 5000
""", {"plane.stl": PLANE, "disc.stl": LOW_DISC},
        ("check/contact: step 3110: particle 2 overlaps mesh plane by 0.301 of its radius, above max_wall_overlap = 0.3",)),
    # fix squeeze/ledger's crossing guard
    "max_crossed": (RANK_ONE_HEADER + corotating_walls(["plane"]) +
                    _two_particles((0.003, 0.0002, 1.01 * RADIUS)) + """fix push mover move linear 0 0 -0.1
fix squeeze all squeeze/ledger walls walls records squeezes.txt max_crossed 0
run 12000
""", {"plane.stl": PLANE, "disc.stl": LOW_DISC},
        ("fix squeeze squeeze/ledger: particle 2 has its centre behind the surface of wall plane at (0.003, 0.0002,",
         "1 crossings exceed max_crossed = 0")),
    # fix wall/gran/corotating's contact capacity: raised by the rank that owns the particle alone
    # (error->one), in the wedge where the particle touches both walls at once
    "max_contacts": (RANK_ONE_HEADER + corotating_walls(["wall_a", "wall_b"], "max_contacts 1") +
                     _two_particles((0.003, 0.0, 1.01 * RADIUS / _S)) + """fix push mover move linear 0 0 -0.1
run 2000
""", {"wall_a.stl": WEDGE_A, "wall_b.stl": WEDGE_B, "disc.stl": LOW_DISC},
        ("ERROR on proc 1: fix walls wall/gran/corotating: particle 2 touches more than max_contacts = 1 screw "
         "triangles at once",)),
}
