"""What gmsh does for the generator: discretise circular-arc chains (the screw profile, the twin
bore) and triangulate planar polygons (faces between staggered discs, end caps, the inlet wall).

All 2-D work happens in the z = 0 plane of a throw-away gmsh model; callers map the (u, v) results
onto their planes. Boundary nodes of planar polygons are exactly the points passed in: every
boundary line is a transfinite curve with two nodes, so gmsh adds nodes only inside.
"""
from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager

import gmsh
import numpy as np

from .profile import Arc


@contextmanager
def gmsh_model(name: str) -> Iterator[None]:
    """A fresh, silent gmsh model; gmsh is initialised here if nobody else did it."""
    owner = not gmsh.isInitialized()
    if owner:
        gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)  # deterministic node numbering
    gmsh.model.add(name)
    try:
        yield
    finally:
        gmsh.model.remove()
        if owner:
            gmsh.finalize()


def chord_angle(radius: float, tolerance: float) -> float:
    """Largest angle a chord of a circle of `radius` may subtend so its sagitta stays <= tolerance."""
    return 2.0 * float(np.arccos(1.0 - min(tolerance / radius, 1.0)))


def discretise_arc_chain(pieces: Sequence[Arc], tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes along consecutive arcs (each < 180 degrees), sagitta <= tolerance on every chord.

    Each piece is split into equal-angle chords; consecutive pieces share their junction node.
    Returns the nodes of the open chain, shape (n, 2) - first node of the first piece up to, but not
    including, the last node of the last piece (callers close or continue the chain) - and the
    index of each piece's first node.
    """
    with gmsh_model("arc-chain"):
        geo = gmsh.model.geo
        curves = []
        for arc in pieces:
            ends = arc.points(np.array([0.0, 1.0]))
            start = geo.addPoint(ends[0, 0], ends[0, 1], 0.0)
            centre = geo.addPoint(arc.centre[0], arc.centre[1], 0.0)
            end = geo.addPoint(ends[1, 0], ends[1, 1], 0.0)
            curve = geo.addCircleArc(start, centre, end)
            segments = max(1, int(np.ceil(abs(arc.sweep) / chord_angle(arc.radius, tolerance))))
            geo.mesh.setTransfiniteCurve(curve, segments + 1)
            curves.append(curve)
        geo.synchronize()
        gmsh.model.mesh.generate(1)
        chain = []
        for arc, curve in zip(pieces, curves):
            _, coords, params = gmsh.model.mesh.getNodes(1, curve, includeBoundary=True,
                                                         returnParametricCoord=True)
            nodes = np.asarray(coords).reshape(-1, 3)[np.argsort(params), :2]
            # the junction points are ours, not gmsh's re-evaluation of the arc
            nodes[0], nodes[-1] = arc.points(np.array([0.0, 1.0]))
            chain.append(nodes[:-1])
        starts = np.cumsum([0] + [len(nodes) for nodes in chain[:-1]])
        return np.vstack(chain), starts


def triangulate_polygons(polygons: Sequence[np.ndarray], labels: Sequence[np.ndarray]
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Triangulate simple planar polygons whose boundary nodes carry integer labels.

    polygons[k]: (n_k, 2) boundary nodes in order (either orientation); labels[k]: (n_k,) ids,
    equal ids meaning the same node (shared corners of neighbouring polygons).
    Returns (interior_nodes (m, 2), triangles (t, 3), polygon_of_triangle (t,)). Triangle corners
    are boundary labels when >= 0 and interior nodes -1 - j (index j into interior_nodes) when < 0.
    Triangles are counter-clockwise in (u, v).
    """
    with gmsh_model("planar"):
        geo = gmsh.model.geo
        point_of_label: dict[int, int] = {}
        surfaces = []
        for nodes, ids in zip(polygons, labels):
            spacing = _local_spacing(nodes)
            for node, label, size in zip(nodes, ids, spacing):
                if int(label) not in point_of_label:
                    point_of_label[int(label)] = geo.addPoint(node[0], node[1], 0.0, size)
            points = [point_of_label[int(label)] for label in ids]
            lines = [geo.addLine(points[i], points[(i + 1) % len(points)]) for i in range(len(points))]
            for line in lines:
                geo.mesh.setTransfiniteCurve(line, 2)
            surfaces.append(geo.addPlaneSurface([geo.addCurveLoop(lines)]))
        geo.synchronize()
        gmsh.model.mesh.generate(2)

        label_of_node = {}
        for label, point in point_of_label.items():
            node_tags, _, _ = gmsh.model.mesh.getNodes(0, point)
            label_of_node[int(node_tags[0])] = label
        interior_tags, interior_coords, _ = gmsh.model.mesh.getNodes(2, -1)
        interior = np.asarray(interior_coords).reshape(-1, 3)[:, :2]
        for j, tag in enumerate(interior_tags):
            label_of_node[int(tag)] = -1 - j

        all_triangles, owners = [], []
        for k, surface in enumerate(surfaces):
            _, element_nodes = gmsh.model.mesh.getElementsByType(2, surface)
            corners = np.array([label_of_node[int(t)] for t in element_nodes], dtype=np.int64)
            all_triangles.append(corners.reshape(-1, 3))
            owners.append(np.full(len(corners) // 3, k))
        triangles = np.vstack(all_triangles)
        polygon_of_triangle = np.concatenate(owners)

    corners = _corner_coordinates(triangles, polygons, labels, interior)
    edge1, edge2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    clockwise = edge1[:, 0] * edge2[:, 1] - edge1[:, 1] * edge2[:, 0] < 0
    triangles[clockwise] = triangles[clockwise][:, ::-1]
    return interior, triangles, polygon_of_triangle


def _local_spacing(nodes: np.ndarray) -> np.ndarray:
    """Mesh size at each boundary node: the mean length of its two boundary edges."""
    edge = np.linalg.norm(np.roll(nodes, -1, axis=0) - nodes, axis=1)
    return 0.5 * (edge + np.roll(edge, 1))


def _corner_coordinates(triangles: np.ndarray, polygons: Sequence[np.ndarray],
                        labels: Sequence[np.ndarray], interior: np.ndarray) -> np.ndarray:
    """(t, 3, 2) coordinates of triangle corners given as boundary labels or -1 - interior index."""
    boundary_labels = np.concatenate([np.asarray(ids) for ids in labels])
    boundary_nodes = np.vstack(polygons)
    unique_labels, first = np.unique(boundary_labels, return_index=True)
    on_boundary = triangles >= 0
    corners = np.empty(triangles.shape + (2,))
    rows = first[np.searchsorted(unique_labels, triangles[on_boundary])]
    corners[on_boundary] = boundary_nodes[rows]
    corners[~on_boundary] = interior[-1 - triangles[~on_boundary]]
    return corners
