"""Bad input to the LIGGGHTS core as this project uses it: EEPA properties (stock number parsing and
our range checks), mesh files (the patched STL/VTK reader), fix wall/gran/corotating, and the same
errors on 2 ranks. Rows of the bad-input campaign (tests/errors/README.md)."""
from __future__ import annotations

import struct

from badinput import BadInput
from tsg_cases.eepa_contact import INPUTS, Eepa

# ---- EEPA properties ------------------------------------------------------------------------------
IMPACT = (INPUTS / "in.two_sphere_impact").read_text()
PROPERTY_FIX = {"plasticityRatio": "e1", "pullOffForce": "e2", "surfaceEnergy": "e3", "slopeExponent": "e4",
                "tensionExponent": "e5", "tangentialStiffnessMultiplier": "e6"}


def eepa(id: str, name: str, value: str, words: tuple[str, ...], why: str, nprocs: int = 1) -> BadInput:
    """The two-sphere impact with one EEPA property replaced by `value` (as written in the input)."""
    include = "\n".join(f"fix {PROPERTY_FIX[name]} all property/global {name} peratomtypepair 1 {value}"
                        if f" {name} " in line else line for line in Eepa().include().splitlines())
    return BadInput(f"lmp.eepa.{id}", words, why=why, lmp_input=IMPACT, files={"model.include": include + "\n"},
                    variables={"v": 0.1, "nsteps": 10, "dt": 1e-8}, nprocs=nprocs)


def not_a_number(name: str, value: str, nprocs: int = 1) -> BadInput:
    return eepa(f"{name}-{value}" + ("-np2" if nprocs > 1 else ""), name, value,
                ("Expected floating point parameter", f"got '{value}'",
                 f"{PROPERTY_FIX[name]} all property/global {name}"),
                "a property that is not a number must be named, not read as 0 or reported anonymously", nprocs)


EEPA = [not_a_number(name, "nan") for name in PROPERTY_FIX] + [
    not_a_number("plasticityRatio", "0,5"),
    not_a_number("slopeExponent", "1.5.1"),
    not_a_number("surfaceEnergy", "high"),
    not_a_number("tensionExponent", "1e999"),
    not_a_number("pullOffForce", "nan", nprocs=2),
] + [eepa(f"{name}-{value}", name, value, (f"atom types 1 1: {name} = {shown} is outside the allowed range {allowed}",),
          why, nprocs=1) for name, value, shown, allowed, why in [
    ("plasticityRatio", "1.0", "1", "[0, 1)", "λp = 1 makes the unloading stiffness infinite"),
    ("plasticityRatio", "-0.1", "-0.1", "[0, 1)", "a negative plasticity ratio unloads softer than it loads"),
    ("slopeExponent", "0.9", "0.9", "[1, inf)", "n < 1 has an infinite stiffness at first touch"),
    ("tensionExponent", "0.5", "0.5", "[1, inf)", "X < 1 has an infinite adhesive stiffness at the pull-off point"),
    ("surfaceEnergy", "-1", "-1", "[0, inf)", "a negative surface energy repels"),
    ("pullOffForce", "0.001", "0.001", "(-inf, 0]", "a positive constant pull-off force repels"),
    ("tangentialStiffnessMultiplier", "0", "0", "(0, inf)", "a zero tangential stiffness has no friction"),
    ("tangentialStiffnessMultiplier", "-1e-9", "-1e-9", "(0, inf)",
     "a negative multiplier; formatted like the others (std::to_string printed -0.000000)"),
]] + [
    BadInput("lmp.eepa.property-missing", ("tensionExponent",), why="every EEPA property is needed",
             lmp_input=IMPACT, files={"model.include": "\n".join(
                 l for l in Eepa().include().splitlines() if "tensionExponent" not in l) + "\n"},
             variables={"v": 0.1, "nsteps": 10, "dt": 1e-8}),
]

# ---- mesh files -----------------------------------------------------------------------------------
MESH_BOX = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block -0.02 0.02 -0.02 0.02 -0.02 0.02 units box
create_box 1 box
fix m1 all property/global youngsModulus peratomtype 5.0e7
fix m2 all property/global poissonsRatio peratomtype 0.25
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
"""


def facet(a: str = "0 0 0", b: str = "0 0.01 0", c: str = "0 0.01 0.01") -> str:
    return f"facet normal 1 0 0\n outer loop\n  vertex {a}\n  vertex {b}\n  vertex {c}\n endloop\nendfacet\n"


def solid(*facets: str) -> str:
    return "solid part\n" + "".join(facets) + "endsolid part\n"


GOOD_STL = solid(facet(), facet("0 0 0", "0 0.01 0.01", "0 0 0.01"))


def binary_stl(triangles: int, announced: int) -> bytes:
    body = b"".join(struct.pack("<12fH", 1, 0, 0, 0, 0, 0, 0, 0.01, 0, 0, 0.01, 0.01, 0) for _ in range(triangles))
    return b"binary part".ljust(80, b" ") + struct.pack("<I", announced) + body


def mesh(id: str, content: str | bytes, words: tuple[str, ...], why: str, nprocs: int = 1) -> BadInput:
    """A plain `fix mesh/surface` of the broken file (every mesh goes through the same reader)."""
    return BadInput(f"lmp.mesh.{id}", ("mesh file 'part.stl'",) + words, why=why,
                    lmp_input=MESH_BOX + "fix part all mesh/surface file part.stl type 1\n",
                    files={"part.stl": content}, nprocs=nprocs)


MESHES = [
    mesh("decimal-comma", solid(facet(b="0 0,01 0")), ("line 5", "vertex coordinate '0,01' is not a number"),
         "atof read '0,01' as 0: the mesh was silently flattened"),
    mesh("units", solid(facet(b="0 10mm 0")), ("line 5", "vertex coordinate '10mm' is not a number"),
         "coordinates are plain numbers in the units of the run"),
    mesh("nan", solid(facet(b="0 nan 0")), ("line 5", "vertex coordinate 'nan' is not a number"),
         "a NaN vertex poisons every contact with the triangle"),
    mesh("two-numbers", solid(facet(b="0 0.01")), ("line 5", "expected 'vertex x y z', found 2 values"),
         "a vertex has three coordinates"),
    mesh("two-vertices", solid(facet().replace("  vertex 0 0.01 0.01\n", "")),
         ("line 7", "facet with 2 vertices (a triangle has 3)"), "only triangles are supported"),
    mesh("four-vertices", solid(facet().replace(" endloop", "  vertex 0 0 0.01\n endloop")),
         ("line 7", "more than 3 vertices in a facet"), "only triangles are supported"),
    mesh("unknown-keyword", solid(facet()).replace(" outer loop", " outer loop\n  colour red"),
         ("line 4", "unknown keyword 'colour'"), "a line the reader does not understand was skipped silently"),
    mesh("no-normal", solid(facet()).replace("facet normal 1 0 0", "facet"), ("line 2", "expected 'facet normal nx ny nz'"),
         "upstream read past the end of the line"),
    mesh("empty", "", ("is empty (no triangles)",), "an empty mesh is a wall that is not there"),
    mesh("blank", "\n\n", ("is empty (no triangles)",), "an empty mesh is a wall that is not there"),
    mesh("truncated", GOOD_STL[: GOOD_STL.index(" endloop")], ("ends at line 6 inside a loop (truncated?)",),
         "a truncated file lost its last triangles"),
    mesh("no-triangles", "solid part\nendsolid part\n", ("holds no triangles",), "a mesh without triangles is no wall"),
    mesh("not-stl", "this is not a mesh\n", ("neither an ASCII STL file", "nor a binary one"),
         "a text file without 'solid' was read as a binary STL"),
    mesh("binary-truncated", binary_stl(1, 3), ("binary STL file ends after 1 of the 3 triangles",),
         "a truncated binary file lost triangles"),
    mesh("binary-zero", binary_stl(0, 0), ("binary STL file with no triangles",), "a mesh without triangles is no wall"),
    mesh("decimal-comma-np2", solid(facet(b="0 0,01 0")), ("line 5", "vertex coordinate '0,01' is not a number"),
         "the same message on 2 ranks", nprocs=2),
    BadInput("lmp.mesh.missing", ("Cannot open mesh file 'nope.stl' (missing or not readable)",),
             why="the mesh file must exist", lmp_input=MESH_BOX + "fix part all mesh/surface file nope.stl type 1\n"),
]

# ---- fix wall/gran/corotating ----------------------------------------------------------------------
COROTATING = MESH_BOX + """fix screw all mesh/surface file screw.stl type 1
fix barrel all mesh/surface file barrel.stl type 1
fix walls all wall/gran/corotating model hertz tangential history mesh n_meshes 2 meshes screw barrel &
    corotate screw origin 0 0 0 axis 1 0 0 period {period} fixed barrel {extra}
create_atoms 1 single 0.001 0.001 0.001 units box
set atom * diameter 0.001 density 2500
fix integr all nve/sphere
timestep 1e-6
run 1
"""


def corotating(id: str, words: tuple[str, ...], why: str, period: str = "0.1", extra: str = "",
               barrel: str = GOOD_STL) -> BadInput:
    return BadInput(f"lmp.corotating.{id}", words, why=why, lmp_input=COROTATING.format(period=period, extra=extra),
                    files={"screw.stl": GOOD_STL, "barrel.stl": barrel})


COROTATING_ROWS = [
    corotating("barrel-decimal-comma", ("mesh file 'barrel.stl', line 5", "vertex coordinate '0,01' is not a number"),
               "a fixed barrel goes through the same reader as the screws", barrel=solid(facet(b="0 0,01 0"))),
    corotating("barrel-empty", ("mesh file 'barrel.stl' is empty",), "a fixed barrel that is not there", barrel=""),
    corotating("period-zero", ("corotate screw: period = 0 is not allowed",), "a screw that does not turn", period="0"),
    corotating("period-nan", ("corotate screw: period = 'nan' is not a finite number",), "a NaN pose", period="nan"),
    corotating("max-contacts-zero", ("max_contacts = 0 is not allowed: an integer from 1 to 1000",),
               "room for no contact", extra="max_contacts 0"),
    corotating("unknown-keyword", ("unknown keyword 'speed'", "allowed: corotate, fixed"),
               "a misspelt keyword must not be ignored", extra="speed 3"),
    corotating("off-axis", ("mesh 'screw' does not share the rotation axis",),
               "a screw turned about another axis sweeps through the barrel"),
]

# ---- an error raised on rank 1 only, during a run: the log holds it and rank 0's thermo before it ----
def x_screw() -> str:
    """Two planes through the x axis at +-45 degrees (an X in cross-section; area centroid on the axis):
    a particle sliding into the wedge touches two non-coplanar triangles at once."""
    h = 0.01 / 2**0.5
    out = ["solid x"]
    for z0, dz in ((-h, 2 * h), (h, -2 * h)):
        corners = [(0, -h, z0), (0.1, -h, z0), (0.1, h, z0 + dz), (0, h, z0 + dz)]
        for tri in ((0, 1, 2), (0, 2, 3)):
            out += ["facet normal 0 0 0", " outer loop"] + \
                   ["  vertex %r %r %r" % corners[k] for k in tri] + [" endloop", "endfacet"]
    return "\n".join(out + ["endsolid x"]) + "\n"


RANK1 = MESH_BOX.replace("region box block -0.02 0.02", "processors 2 1 1\nregion box block 0 0.1") + """neighbor 0.0002 bin
neigh_modify delay 0
fix screw all mesh/surface file screw.stl type 1
fix barrel all mesh/surface file barrel.stl type 1
fix walls all wall/gran/corotating model hertz tangential history mesh n_meshes 2 meshes screw barrel &
    corotate screw origin 0 0 0 axis 1 0 0 period 100 fixed barrel max_contacts 1
create_atoms 1 single 0.075 0 0.00072 units box
set atom * diameter 0.001 density 2500
velocity all set 0 0 -0.01 units box
fix integr all nve/sphere
timestep 1e-6
thermo_style custom step atoms
thermo 100
run 3000
"""

MPI = [
    BadInput("lmp.mpi.rank1-max-contacts-mid-run",
             ("800 1", "1100 1", "ERROR on proc 1: fix walls wall/gran/corotating: particle 1 touches more than "
                                 "max_contacts = 1 screw triangles at once"),
             why="an error of rank 1 (the particle is there) reached only stderr and rank 0's thermo was lost",
             lmp_input=RANK1, files={"screw.stl": x_screw(), "barrel.stl": GOOD_STL}, nprocs=2),
]

CASES: list[BadInput] = EEPA + MESHES + COROTATING_ROWS + MPI
