"""Indexed triangle surfaces: assembly, ASCII STL output/input, and the checks LIGGGHTS cares about."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class TriangleMesh:
    """Shared vertices (n, 3) and triangles (t, 3) whose normals (right-hand rule) face the particles.

    `part` labels each triangle (an element index for screws, 0 for the barrel) and `kind` says
    whether it lies on a swept wall (deviation from the exact profile applies) or on a plane.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    part: np.ndarray
    kind: np.ndarray  # WALL or PLANE

    WALL = 0
    PLANE = 1

    @property
    def corners(self) -> np.ndarray:
        return self.vertices[self.triangles]

    def normals(self) -> np.ndarray:
        c = self.corners
        n = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
        return n / np.linalg.norm(n, axis=1, keepdims=True)


class MeshBuilder:
    """Accumulates vertices and triangles block by block (vertex ids are global, in creation order)."""

    def __init__(self) -> None:
        self._vertices: list[np.ndarray] = []
        self._count = 0
        self._triangles: list[np.ndarray] = []
        self._part: list[np.ndarray] = []
        self._kind: list[np.ndarray] = []

    def add_vertices(self, points: np.ndarray) -> np.ndarray:
        ids = np.arange(self._count, self._count + len(points))
        self._vertices.append(np.asarray(points, dtype=float))
        self._count += len(points)
        return ids

    def add_triangles(self, triangles: np.ndarray, part: int, kind: int) -> None:
        triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
        self._triangles.append(triangles)
        self._part.append(np.full(len(triangles), part, dtype=np.int64))
        self._kind.append(np.full(len(triangles), kind, dtype=np.int8))

    def build(self) -> TriangleMesh:
        return TriangleMesh(np.vstack(self._vertices), np.vstack(self._triangles),
                            np.concatenate(self._part), np.concatenate(self._kind))


def write_ascii_stl(mesh: TriangleMesh, path: Path | str, solid_name: str) -> None:
    """ASCII STL in metres, as `fix mesh/surface file ... type 1` reads it. Same mesh, same bytes."""
    rows = np.concatenate([mesh.normals(), mesh.corners.reshape(-1, 9)], axis=1)
    facet = ("facet normal %.7e %.7e %.7e\n outer loop\n"
             "  vertex %.10e %.10e %.10e\n  vertex %.10e %.10e %.10e\n  vertex %.10e %.10e %.10e\n"
             " endloop\nendfacet\n")
    chunk = 20000  # bounded memory for the formatted text of very fine meshes
    with open(path, "w", encoding="ascii", newline="\n") as out:
        out.write(f"solid {solid_name}\n")
        for start in range(0, len(rows), chunk):
            block = rows[start:start + chunk]
            out.write((facet * len(block)) % tuple(block.ravel()))
        out.write(f"endsolid {solid_name}\n")


def read_ascii_stl(path: Path | str) -> np.ndarray:
    """Triangle corners (t, 3, 3) of an ASCII STL."""
    values = [line.split()[1:] for line in Path(path).read_text().splitlines()
              if line.lstrip().startswith("vertex")]
    return np.asarray(values, dtype=float).reshape(-1, 3, 3)


def smallest_angles_deg(corners: np.ndarray) -> np.ndarray:
    """Smallest interior angle of each triangle, degrees."""
    angles = []
    for k in range(3):
        a = corners[:, (k + 1) % 3] - corners[:, k]
        b = corners[:, (k + 2) % 3] - corners[:, k]
        cosine = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        angles.append(np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))))
    return np.min(angles, axis=0)


def edge_use(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Undirected edges (e, 2), how many triangles use each, and how many of those run it low->high.

    A closed, consistently oriented 2-manifold uses every edge exactly twice, once in each direction.
    """
    directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    ascending = directed[:, 0] < directed[:, 1]
    undirected = np.sort(directed, axis=1)
    edges, inverse, counts = np.unique(undirected, axis=0, return_inverse=True, return_counts=True)
    forward = np.bincount(inverse.ravel(), weights=ascending, minlength=len(edges)).astype(int)
    return edges, counts, forward


def edge_neighbour_counts(triangles: np.ndarray) -> np.ndarray:
    """Per triangle, how many other triangles share one of its edges: what LIGGGHTS counts against
    its limit of 5 neighbours per element (SurfaceMesh<3,5>, handleSharedEdge)."""
    directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    _, inverse, counts = np.unique(np.sort(directed, axis=1), axis=0, return_inverse=True,
                                   return_counts=True)
    per_edge_others = (counts - 1)[inverse.ravel()].reshape(3, -1)
    return per_edge_others.sum(axis=0)
