"""Barrel surface: the twin-bore outline swept straight along x, normals facing into the bore
(towards the particles); open at both ends for periodic domains, closed by a flat inlet wall at
x = 0 for inlet-wall domains (the outlet stays open so particles can leave)."""
from __future__ import annotations

import numpy as np

from .gmsh_engine import discretise_arc_chain, triangulate_polygons
from .profile import Arc, TwinBore
from .screw import MAX_WALL_ASPECT
from .surface import MeshBuilder, TriangleMesh

BARREL_PART = 0


def sample_twin_bore(bore: TwinBore, tolerance: float) -> np.ndarray:
    """Closed outline (counter-clockwise in (y, z)) with chords within `tolerance` of the bores;
    the two cusps are nodes. gmsh arcs must stay below 180 degrees, so each bore arc is cut in 3."""
    pieces = [Arc(arc.centre, arc.radius, arc.start + arc.sweep * k / 3, arc.sweep / 3)
              for arc in bore.arcs for k in range(3)]
    nodes, _ = discretise_arc_chain(pieces, tolerance)
    return nodes


def build_barrel(length: float, inlet_wall: bool, tolerance: float, bore: TwinBore = TwinBore()) -> TriangleMesh:
    """Barrel from x = 0 to x = length (metres)."""
    outline = sample_twin_bore(bore, tolerance)
    m = len(outline)
    segment = np.linalg.norm(np.roll(outline, -1, axis=0) - outline, axis=1)
    planes = int(np.ceil(length / (MAX_WALL_ASPECT * segment.mean())))
    xs = length * np.arange(planes + 1) / planes
    xs[-1] = length  # exactly on the end plane
    builder = MeshBuilder()
    points = np.concatenate([np.column_stack((np.full(m, x), outline)) for x in xs])
    ids = builder.add_vertices(points).reshape(planes + 1, m)
    nxt = np.roll(np.arange(m), -1)
    a, b = ids[:-1], ids[1:]
    # counter-clockwise outline + axial step gives an outward normal (away from the bore axis);
    # the corner order here is reversed so the normals face the bore interior
    first = np.stack((a, b[:, nxt], a[:, nxt]), axis=-1)
    second = np.stack((a, b, b[:, nxt]), axis=-1)
    builder.add_triangles(np.stack((first, second), axis=2).reshape(-1, 3), BARREL_PART, TriangleMesh.WALL)
    if inlet_wall:
        _add_inlet_wall(builder, outline, ids[0])
    return builder.build()


def _add_inlet_wall(builder: MeshBuilder, outline: np.ndarray, ring_ids: np.ndarray) -> None:
    interior, triangles, _ = triangulate_polygons([outline], [ring_ids])
    interior_ids = builder.add_vertices(np.column_stack((np.zeros(len(interior)), interior)))
    # counter-clockwise in (y, z): normal +x, into the barrel
    builder.add_triangles(np.where(triangles >= 0, triangles, interior_ids[np.maximum(-1 - triangles, 0)]),
                          BARREL_PART, TriangleMesh.PLANE)
