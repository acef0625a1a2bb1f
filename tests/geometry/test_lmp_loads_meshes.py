"""The generated meshes in LIGGGHTS: every shipped STL loads without a warning, the periodic
sub-domain runs with rotating screws, and conveying elements convey towards +x with the rotation
sense the meshes assume (omega > 0 about +x)."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from tsg_harness import run_lmp
from tsg_meshes.build import MESH_FILES, build_all, generate, write_geometry
from tsg_meshes.machine import machine_values
from tsg_meshes.profile import LEAD
from tsg_meshes.spec import parse_spec

MACHINE = machine_values()   # the machine.in keys the cases read (one source)
HALF = MACHINE["axis2_y"]
# box around the barrel in y and z (the barrel must lie inside the non-periodic directions)
Y_EXTENT = MACHINE["box_y"]
Z_EXTENT = MACHINE["box_z"]

MATERIALS = """
fix m1 all property/global youngsModulus peratomtype 1.3e7
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.01
pair_style gran model hertz tangential history rolling_friction cdt
pair_coeff * *
"""


def header(length: float, periodic: bool, skin: float = 3e-4) -> str:
    x_lo, x_hi = (0.0, length) if periodic else (-1e-3, length + 1e-3)
    return f"""atom_style    granular
atom_modify   map array sort 0 0
boundary      {'p' if periodic else 'f'} f f
newton        off
communicate   single vel yes
units         si
region        box block {x_lo:.12g} {x_hi:.12g} {-Y_EXTENT:.12g} {Y_EXTENT:.12g} {-Z_EXTENT:.12g} {Z_EXTENT:.12g} units box
create_box    1 box
neighbor      {skin:.12g} bin
neigh_modify  delay 0
{MATERIALS}"""


def load_meshes(rotating: bool) -> str:
    lines = [f"fix {Path(f).stem} all mesh/surface file {f} type 1" for f in MESH_FILES]
    lines.append("fix walls all wall/gran model hertz tangential history rolling_friction cdt "
                 "mesh n_meshes 3 meshes screw1 screw2 barrel")
    if rotating:
        lines += [f"fix turn1 all move/mesh mesh screw1 rotate origin 0 {-HALF:.12g} 0 axis 1 0 0 period 0.1",
                  f"fix turn2 all move/mesh mesh screw2 rotate origin 0 {HALF:.12g} 0 axis 1 0 0 period 0.1"]
    return "\n".join(lines) + "\n"


def triangle_count(stl: Path) -> int:
    return sum(1 for line in stl.read_text().splitlines() if line.startswith("facet"))


def assert_no_mesh_warnings(run) -> None:
    run.assert_clean()
    # some mesh diagnostics go to the screen with a bare "WARNING:" and no source location
    assert "WARNING" not in run.stdout + run.log, re.findall(r".*WARNING.*", run.stdout + run.log)


@pytest.fixture(scope="module")
def shipped(tmp_path_factory) -> list[Path]:
    outdir = tmp_path_factory.mktemp("meshes")
    return sorted({path.parent for path in build_all(outdir)})


def test_every_shipped_mesh_loads_without_warning(shipped, tmp_path):
    assert len(shipped) == 4
    for build_dir in shipped:
        zones = (build_dir / "zones.txt").read_text()
        periodic = "ends periodic" in zones.splitlines()[0]
        length = float(re.search(r"length (\S+) m", zones).group(1))
        text = header(length, periodic) + load_meshes(rotating=False) + "run 0\n"
        run = run_lmp(text, tmp_path / build_dir.name, files={f: build_dir / f for f in MESH_FILES})
        assert_no_mesh_warnings(run)
        for f in MESH_FILES:
            expected = triangle_count(build_dir / f)
            assert f"Import and parallelization of mesh {Path(f).stem} containing {expected} triangle(s) successful" \
                in run.stdout, f"{build_dir.name}/{f}"


def particle_in_channel(x: float, screw: int, phase_1: float, depth: float) -> tuple[float, float, float]:
    """A point in the channel of `screw` at axial x: on a root axis, on the side facing away from
    the other screw, `depth` from the axis (between the root 6.9 mm and the tips 12.06 mm)."""
    axis_y = -HALF if screw == 1 else HALF
    phase = phase_1 + (0.0 if screw == 1 else np.pi / 2)
    roots = phase + np.array([np.pi / 2, 3 * np.pi / 2])
    outward = roots[np.argmax(-np.cos(roots) if screw == 1 else np.cos(roots))]
    return (x, axis_y + depth * np.cos(outward), depth * np.sin(outward))


def particles(config_phase, xs: np.ndarray, diameter: float) -> str:
    lines = [f"create_atoms 1 single {x:.12g} {y:.12g} {z:.12g} units box"
             for x in xs for screw in (1, 2)
             for x, y, z in [particle_in_channel(x, screw, config_phase(x), depth=9.5e-3)]]
    return "\n".join(lines) + f"\nset atom * diameter {diameter:.12g} density 1263\n"


def test_periodic_subdomain_runs_with_rotating_screws(tmp_path):
    geometry = generate(parse_spec((Path(__file__).parents[2] / "meshes/configs/consigma1-periodic.spec").read_text()))
    write_geometry(geometry, tmp_path / "meshes")
    conveying = geometry.configuration.elements[0]
    xs = np.linspace(0.1, 0.9, 6) * float(conveying.length_mm) / 1000
    text = (header(geometry.length, periodic=True) + load_meshes(rotating=True)
            + particles(lambda x: float(conveying.phase_at(x)), xs, 6e-4)
            + "fix grav all gravity 9.81 vector 0 0 -1\nfix integr all nve/sphere\ntimestep 2e-6\n"
            + "thermo_style custom step atoms ke\nthermo_modify lost error\nthermo 50\nrun 200\n")
    run = run_lmp(text, tmp_path / "run", files={f: tmp_path / "meshes" / f for f in MESH_FILES})
    assert_no_mesh_warnings(run)
    assert run.thermo[-1]["Atoms"][-1] == 2 * len(xs)


def test_conveying_element_conveys_downstream(tmp_path):
    """One lead of conveying element, periodic, coarse mesh: over half a revolution at omega > 0
    the particles in the channels advance towards +x (the opposite sense sends them to -x)."""
    geometry = generate(parse_spec("name conveying\nends periodic\nelements C1\n"), tolerance=5e-5)
    write_geometry(geometry, tmp_path / "meshes")
    element = geometry.configuration.elements[0]
    xs = (np.arange(12) + 0.5) / 12 * LEAD
    text = (header(geometry.length, periodic=True) + load_meshes(rotating=True)
            + particles(lambda x: float(element.phase_at(x)), xs, 6e-4)
            + "fix grav all gravity 9.81 vector 0 0 -1\nfix integr all nve/sphere\ntimestep 2e-6\n"
            + "variable xc equal xcm(all,x)\nthermo_style custom step atoms v_xc\nthermo_modify lost error\n"
            + "thermo 1000\nrun 25000\n")
    run = run_lmp(text, tmp_path / "run", files={f: tmp_path / "meshes" / f for f in MESH_FILES})
    run.assert_clean()
    centre = run.thermo[-1]["xc"]  # LIGGGHTS prints v_xc as "xc"
    assert run.thermo[-1]["Atoms"][-1] == 2 * len(xs)
    # the flights sweep 12.5 mm downstream per half revolution; the particles they push follow
    # (measured: +5.3 mm over the half revolution; -5.2 mm with period -0.1)
    assert centre[-1] - centre[0] > 3e-3, centre
