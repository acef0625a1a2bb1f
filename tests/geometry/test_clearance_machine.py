"""A clearance-scaled machine (`python -m tsg_meshes build ... --clearance C`): the gaps measured in
3D on the written STL files, independently of the profile formulas and of the section analysis.

Distances are VTK's exact point-to-triangle distances from one mesh's vertices to another mesh,
with the screws turned as they co-rotate. Measured: flight tip to barrel and screw to screw within
an element equal C (to the chordal tolerance); the paper's machine keeps 0.44 / 0.35 mm. At a
phase jump between kneading discs the two screws' end faces lie in one plane and their edges
cross: there the screw-to-screw distance is zero for every C (a scissor; docs/stability-demo.md).
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from conftest import built
from tsg_meshes.build import DEFAULT_TOLERANCE, generate, mesh_dir_name, write_geometry
from tsg_meshes.machine import read_machine
from tsg_meshes.profile import profile_for_clearance
from tsg_meshes.spec import read_spec
from tsg_meshes.build import resolve_config

pv = pytest.importorskip("pyvista")
vtk_core = pytest.importorskip("vtkmodules.vtkFiltersCore")

CLEARANCE = 1.4e-3          # the demo scale's (cases/run_case.py SCALES)
ANGLES_DEG = (0.0, 17.0, 45.0, 73.0, 90.0, 131.0)   # the profile repeats after 180 deg
SLAB = 1.2e-3               # half width of the axial slab of vertices measured per element


@pytest.fixture(scope="module")
def clearance_machine(tmp_path_factory):
    geometry = generate(read_spec(resolve_config("consigma1-periodic")), DEFAULT_TOLERANCE,
                        profile_for_clearance(CLEARANCE))
    out = tmp_path_factory.mktemp("c") / mesh_dir_name("consigma1-periodic", DEFAULT_TOLERANCE, CLEARANCE)
    write_geometry(geometry, out)
    return geometry, out


def distance_to(mesh_file, points: np.ndarray) -> np.ndarray:
    from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    function = vtk_core.vtkImplicitPolyDataDistance()
    function.SetInput(pv.read(mesh_file))
    values = vtkDoubleArray()
    function.FunctionValue(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True), values)
    return np.abs(vtk_to_numpy(values))


def turn(points: np.ndarray, axis_y: float, angle: float) -> np.ndarray:
    """Points turned by `angle` about the x-parallel axis through (y, z) = (axis_y, 0)."""
    c, s = np.cos(angle), np.sin(angle)
    y, z = points[:, 1] - axis_y, points[:, 2]
    return np.column_stack((points[:, 0], axis_y + c * y - s * z, s * y + c * z))


def vertices(stl, x_ranges) -> np.ndarray:
    points = np.unique(pv.read(stl).points.astype(np.float64), axis=0)
    keep = np.zeros(len(points), dtype=bool)
    for low, high in x_ranges:
        keep |= (points[:, 0] > low) & (points[:, 0] < high)
    return points[keep]


def element_slabs(geometry) -> list[tuple[float, float]]:
    """An axial slab in the middle of the first conveying element and of each kneading disc."""
    slabs = []
    for element in geometry.configuration.elements:
        if element.kind == "kneading" or element.index == 1:
            middle = float(element.x_start_mm + element.length_mm / 2) / 1000
            slabs.append((middle - SLAB, middle + SLAB))
    return slabs


def gaps(directory, x_ranges) -> tuple[float, float]:
    """Smallest screw-barrel and screw-screw distances over the co-rotation angles, from the
    vertices of both screws in `x_ranges`."""
    machine = read_machine(directory)
    axes = (machine["axis1_y"], machine["axis2_y"])
    barrel, screw = np.inf, np.inf
    for angle in np.radians(ANGLES_DEG):
        for mine, other in ((0, 1), (1, 0)):
            points = turn(vertices(directory / f"screw{mine + 1}.stl", x_ranges), axes[mine], angle)
            barrel = min(barrel, distance_to(directory / "barrel.stl", points).min())
            # into the frame where the other screw is at its written phase
            in_other = turn(points, axes[other], -angle)
            screw = min(screw, distance_to(directory / f"screw{other + 1}.stl", in_other).min())
    return barrel, screw


def test_machine_file_states_the_requested_clearances(clearance_machine):
    _, directory = clearance_machine
    machine = read_machine(directory)
    assert directory.name == "consigma1-periodic-5um-c1.4mm"
    assert machine["barrel_clearance"] == pytest.approx(CLEARANCE, abs=1e-12)
    assert machine["screw_clearance"] == pytest.approx(CLEARANCE, abs=1e-12)
    assert machine["bore_radius"] - machine["screw_outer_radius"] == pytest.approx(CLEARANCE, abs=1e-12)
    assert machine["centre_distance"] == pytest.approx(19.31e-3, abs=1e-12)


def test_gaps_within_elements_equal_the_clearance(clearance_machine):
    geometry, directory = clearance_machine
    barrel, screw = gaps(directory, element_slabs(geometry))
    # vertices lie on the exact surface, so a vertex-to-mesh distance is the gap to within the
    # chordal tolerance of the mesh it is measured to (and the vertex spacing around the nearest point)
    assert barrel == pytest.approx(CLEARANCE, abs=2 * DEFAULT_TOLERANCE)
    assert screw == pytest.approx(CLEARANCE, abs=2 * DEFAULT_TOLERANCE + 2e-5)


def test_paper_machine_keeps_its_gaps(tmp_path):
    geometry = built("consigma1-periodic")
    write_geometry(geometry, tmp_path)
    barrel, screw = gaps(tmp_path, element_slabs(geometry))
    assert barrel == pytest.approx(0.44e-3, abs=2 * DEFAULT_TOLERANCE)
    assert screw == pytest.approx(0.35e-3, abs=2 * DEFAULT_TOLERANCE + 2e-5)


def test_disc_faces_of_the_two_screws_meet_at_a_phase_jump(clearance_machine):
    """The scissor that no clearance removes: at the plane between two staggered discs, screw 1's
    disc and screw 2's next disc overlap in projection, so their coplanar faces touch."""
    geometry, directory = clearance_machine
    discs = [e for e in geometry.configuration.elements if e.kind == "kneading"]
    plane = float(discs[len(discs) // 2].x_start_mm) / 1000
    _, screw = gaps(directory, [(plane - 1e-9, plane + 1e-9)])
    assert screw < 2 * DEFAULT_TOLERANCE
