"""Deviation from the exact surface, triangle shape, topology and periodic matching of the meshes."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import SHIPPED
from tsg_meshes.analysis import barrel_wall_deviation, screw_wall_deviation
from tsg_meshes.build import DEFAULT_TOLERANCE, FINE_TOLERANCE, write_geometry
from tsg_meshes.profile import ScrewProfile, TwinBore
from tsg_meshes.surface import (TriangleMesh, edge_neighbour_counts, edge_use, read_ascii_stl,
                                smallest_angles_deg)

PROFILE = ScrewProfile()


@pytest.mark.parametrize("name, tolerance", [(name, DEFAULT_TOLERANCE) for name in SHIPPED]
                         + [("consigma1-periodic", FINE_TOLERANCE), ("consigma1-periodic", 2e-5)])
def test_walls_within_tolerance_of_exact_surface(build, name, tolerance):
    geometry = build(name, tolerance)
    for screw, mesh in enumerate(geometry.screws, start=1):
        deviation = screw_wall_deviation(mesh, geometry.configuration, screw)
        assert deviation.max() <= tolerance, f"screw {screw}: {deviation.max() * 1e6:.3f} um"
        assert deviation.max() >= 0.5 * tolerance  # the tolerance is used, not wasted
    assert barrel_wall_deviation(geometry.barrel).max() <= tolerance


@pytest.mark.parametrize("name", SHIPPED)
def test_triangles_acceptable_to_liggghts(build, name):
    for file, mesh in build(name).meshes().items():
        assert smallest_angles_deg(mesh.corners).min() > 10.0, file  # LIGGGHTS warns below 0.5
        assert edge_neighbour_counts(mesh.triangles).max() <= 3, file  # LIGGGHTS allows 5
        assert len(np.unique(np.sort(mesh.triangles, axis=1), axis=0)) == len(mesh.triangles), file


def open_edge_planes(mesh: TriangleMesh) -> tuple[set[float], bool]:
    """x of the planes holding the open (once-used) edges; and whether every other edge is used
    exactly twice, once in each direction (closed, consistently oriented)."""
    edges, uses, ascending = edge_use(mesh.triangles)
    closed_ok = bool(np.all(uses <= 2) and np.all(ascending[uses == 2] == 1))
    open_x = mesh.vertices[edges[uses == 1]][:, :, 0]
    planes = set(np.unique(open_x).tolist())
    return planes, closed_ok


@pytest.mark.parametrize("name", SHIPPED)
def test_watertight_where_closed(build, name):
    geometry = build(name)
    length = geometry.length
    periodic = geometry.configuration.ends == "periodic"
    for file, mesh in geometry.meshes().items():
        planes, closed_ok = open_edge_planes(mesh)
        assert closed_ok, file
        if periodic:
            expected = {0.0, length}
        else:  # screws open under the inlet wall, barrel open at the outlet
            expected = {length} if file == "barrel.stl" else {0.0}
        assert planes == expected, file
        assert mesh.vertices[:, 0].min() == 0.0 and mesh.vertices[:, 0].max() == length, file


def end_plane_edges(open_edges: np.ndarray, x: float) -> np.ndarray:
    """(y, z) of the open edges lying in the plane x, as rows (y0, z0, y1, z1) in a canonical order
    (each edge's endpoints sorted, then the edges), so that equal edge sets give equal arrays."""
    edges = open_edges[np.all(open_edges[:, :, 0] == x, axis=1)][:, :, 1:]
    swap = np.lexsort((edges[:, :, 1].T, edges[:, :, 0].T), axis=0)[0] == 1
    edges[swap] = edges[swap][:, ::-1]
    rows = edges.reshape(-1, 4)
    return rows[np.lexsort(rows.T[::-1])]


@pytest.mark.parametrize("tolerance", [DEFAULT_TOLERANCE, FINE_TOLERANCE])
def test_periodic_end_planes_match(build, tolerance):
    """Screws and barrel meet themselves across the periodic boundary node for node, bit for bit."""
    geometry = build("consigma1-periodic", tolerance)
    for file, mesh in geometry.meshes().items():
        edges, uses, _ = edge_use(mesh.triangles)
        open_edges = mesh.vertices[edges[uses == 1]]
        inlet, outlet = end_plane_edges(open_edges, 0.0), end_plane_edges(open_edges, geometry.length)
        assert 2 * len(inlet) == 2 * len(outlet) == len(open_edges), file
        assert np.array_equal(inlet, outlet), file


def exact_uncovered_area(stagger: float) -> float:
    """Area of a profile section not covered by the same profile turned by `stagger` (radians)."""
    phi = np.linspace(0, 2 * np.pi, 2_000_001)
    difference = PROFILE.radius(phi) ** 2 - PROFILE.radius(phi - stagger) ** 2
    return float(np.trapezoid(np.maximum(difference, 0.0), phi) / 2)


def plane_face_areas(mesh: TriangleMesh, x: float) -> tuple[float, float]:
    """Areas of the plane triangles at x facing +x and facing -x."""
    corners = mesh.corners
    on_plane = (mesh.kind == TriangleMesh.PLANE) & np.all(corners[:, :, 0] == x, axis=1)
    normal_x = np.cross(corners[on_plane, 1] - corners[on_plane, 0], corners[on_plane, 2] - corners[on_plane, 0])[:, 0]
    return float(normal_x[normal_x > 0].sum() / 2), float(-normal_x[normal_x < 0].sum() / 2)


@pytest.mark.parametrize("name", SHIPPED)
def test_planar_faces_cover_exactly_the_exposed_area(build, name):
    """Between staggered discs each side shows exactly what the other does not cover (no overlapping
    coplanar faces, no holes); caps and the inlet wall cover the screw section and the bore."""
    geometry = build(name)
    elements = geometry.configuration.elements
    uncovered = {}
    for screw in geometry.screws:
        for upstream, downstream in zip(elements, elements[1:]):
            stagger = float(downstream.phase_start_deg - upstream.phase_end_deg) % 180
            if stagger == 0:
                continue
            if stagger not in uncovered:
                uncovered[stagger] = exact_uncovered_area(np.radians(stagger))
            forward, backward = plane_face_areas(screw, float(upstream.x_end_mm) / 1000)
            assert forward == pytest.approx(uncovered[stagger], rel=2e-3)
            assert backward == pytest.approx(uncovered[stagger], rel=2e-3)
        if geometry.configuration.ends == "inlet-wall":
            assert plane_face_areas(screw, geometry.length)[0] == pytest.approx(PROFILE.area_formula(), rel=1e-3)
    if geometry.configuration.ends == "inlet-wall":
        assert plane_face_areas(geometry.barrel, 0.0)[0] == pytest.approx(TwinBore().area_formula(), rel=1e-3)
    assert uncovered, "the shipped configurations all have staggered discs"


def test_stl_files_hold_the_meshes(build, tmp_path):
    geometry = build("consigma1-periodic")
    write_geometry(geometry, tmp_path)
    for file, mesh in geometry.meshes().items():
        text = (tmp_path / file).read_text()
        assert text.startswith(f"solid {file[:-4]}\n") and text.endswith(f"endsolid {file[:-4]}\n")
        np.testing.assert_allclose(read_ascii_stl(tmp_path / file), mesh.corners, rtol=0, atol=1e-12)
