"""Measurements on built meshes: axial sections (area, perimeter, clearances under co-rotation) and
the deviation of the swept walls from the exact surface. Used by the tests and for docs/geometry.md."""
from __future__ import annotations

import numpy as np

from .profile import ScrewProfile, TwinBore
from .screw import ScrewPlacement
from .spec import ScrewConfiguration
from .surface import TriangleMesh


def section_segments(corners: np.ndarray, x: float) -> np.ndarray:
    """Segments (s, 2, 2) in (y, z) where the plane at `x` cuts the triangles (t, 3, 3).

    Each segment runs with its triangle's normal on its right, so the section of a solid whose
    normals point outwards is a counter-clockwise loop (positive area). No vertex may lie on the plane.
    """
    side = corners[:, :, 0] - x
    if np.any(side == 0.0):
        raise ValueError(f"a mesh vertex lies exactly on the section plane x = {x}")
    cut = (np.min(side, axis=1) < 0) & (np.max(side, axis=1) > 0)
    tri, side = corners[cut], side[cut]
    points = np.full((len(tri), 3, 2), np.nan)
    for k in range(3):
        a, b = tri[:, k], tri[:, (k + 1) % 3]
        crosses = side[:, k] * side[:, (k + 1) % 3] < 0
        t = side[crosses, k] / (side[crosses, k] - side[crosses, (k + 1) % 3])
        points[crosses, k] = a[crosses, 1:] + t[:, None] * (b[crosses, 1:] - a[crosses, 1:])
    order = np.argsort(np.isnan(points[:, :, 0]), axis=1, kind="stable")[:, :2]
    segments = np.take_along_axis(points, order[:, :, None], axis=1)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 1:]
    direction = segments[:, 1] - segments[:, 0]
    reverse = direction[:, 1] * normal[:, 0] - direction[:, 0] * normal[:, 1] < 0
    segments[reverse] = segments[reverse][:, ::-1]
    return segments


def signed_area(segments: np.ndarray) -> float:
    p, q = segments[:, 0], segments[:, 1]
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


def perimeter(segments: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)))


def rotate_about(segments: np.ndarray, centre: tuple[float, float], angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    shifted = segments - np.asarray(centre)
    turned = np.stack((c * shifted[..., 0] - s * shifted[..., 1], s * shifted[..., 0] + c * shifted[..., 1]), axis=-1)
    return turned + np.asarray(centre)


def point_segment_distance(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Distance from each point (n, 2) to the nearest of the segments (s, 2, 2)."""
    a, ab = segments[:, 0], segments[:, 1] - segments[:, 0]
    ap = points[:, None, :] - a[None, :, :]
    t = np.clip(np.einsum("nsk,sk->ns", ap, ab) / np.einsum("sk,sk->s", ab, ab), 0.0, 1.0)
    return np.min(np.linalg.norm(ap - t[..., None] * ab[None], axis=2), axis=1)


def gap(segments_a: np.ndarray, segments_b: np.ndarray) -> float:
    """Smallest distance between two closed polylines that do not cross (attained at a vertex)."""
    return float(min(point_segment_distance(segments_a[:, 0], segments_b).min(),
                     point_segment_distance(segments_b[:, 0], segments_a).min()))


def any_crossing(segments_a: np.ndarray, segments_b: np.ndarray) -> bool:
    """Whether any segment of a properly intersects any segment of b."""
    def orient(p, q, r):
        return np.sign((q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0]))
    p, q = segments_a[:, None, 0], segments_a[:, None, 1]
    r, s = segments_b[None, :, 0], segments_b[None, :, 1]
    return bool(np.any((orient(p, q, r) * orient(p, q, s) < 0) & (orient(r, s, p) * orient(r, s, q) < 0)))


def inside(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Even-odd test: which points (n, 2) lie inside the closed polyline given by its segments."""
    a, b = segments[None, :, 0], segments[None, :, 1]
    p = points[:, None, :]
    straddles = (a[..., 1] > p[..., 1]) != (b[..., 1] > p[..., 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        y_cross = a[..., 0] + (p[..., 1] - a[..., 1]) * (b[..., 0] - a[..., 0]) / (b[..., 1] - a[..., 1])
    return np.count_nonzero(straddles & (y_cross > p[..., 0]), axis=1) % 2 == 1


def disjoint(segments_a: np.ndarray, segments_b: np.ndarray) -> bool:
    """Two closed polylines bound disjoint regions: no crossing and neither vertex set inside the other."""
    return not (any_crossing(segments_a, segments_b) or inside(segments_a[:, 0], segments_b).any()
                or inside(segments_b[:, 0], segments_a).any())


def contained(inner: np.ndarray, outer: np.ndarray) -> bool:
    """The region of `inner` lies inside the region of `outer` without touching its boundary."""
    return bool(inside(inner[:, 0], outer).all()) and not any_crossing(inner, outer)


def corotation_clearances(screw1: np.ndarray, screw2: np.ndarray, barrel: np.ndarray,
                          angles: np.ndarray) -> dict[str, np.ndarray]:
    """Turn both screw sections by each angle (omega > 0 about +x) about their own axes and measure
    the screw-screw gap and the smaller screw-barrel gap; flag any overlap."""
    axis1 = (ScrewPlacement.of(1).axis_y, 0.0)
    axis2 = (ScrewPlacement.of(2).axis_y, 0.0)
    screw_gap, barrel_gap, clear = [], [], []
    for angle in angles:
        s1, s2 = rotate_about(screw1, axis1, angle), rotate_about(screw2, axis2, angle)
        screw_gap.append(gap(s1, s2))
        barrel_gap.append(min(gap(s1, barrel), gap(s2, barrel)))
        clear.append(disjoint(s1, s2) and contained(s1, barrel) and contained(s2, barrel))
    return {"screw_gap": np.array(screw_gap), "barrel_gap": np.array(barrel_gap), "clear": np.array(clear)}


def _interior_barycentric(order: int) -> np.ndarray:
    """Barycentric sample points on a triangle, lattice of `order`, vertices left out (exact there)."""
    points = [(i, j, order - i - j) for i in range(order + 1) for j in range(order + 1 - i)]
    return np.array([p for p in points if max(p) < order], dtype=float) / order


def screw_wall_deviation(mesh: TriangleMesh, configuration: ScrewConfiguration, screw: int,
                         profile: ScrewProfile = ScrewProfile(), order: int = 4) -> np.ndarray:
    """Per swept-wall triangle, the largest distance, within the axial section through each sample
    point, from the triangle to the exact profile turned to that section's phase.

    The in-section distance bounds the true 3-D distance from above (the nearest point of the exact
    surface within the section is one candidate), so this is a conservative deviation measure."""
    placement = ScrewPlacement.of(screw, profile)
    walls = mesh.kind == TriangleMesh.WALL
    samples = np.einsum("kb,tbd->tkd", _interior_barycentric(order), mesh.corners[walls])
    element_of = {e.index: e for e in configuration.elements}
    phase = np.empty(samples.shape[:2])
    for index in np.unique(mesh.part[walls]):
        mine = mesh.part[walls] == index
        phase[mine] = element_of[int(index)].phase_at(samples[mine, :, 0])
    phase += np.radians(float(placement.phase_offset_deg))
    y, z = samples[..., 1] - placement.axis_y, samples[..., 2]
    c, s = np.cos(-phase), np.sin(-phase)
    local = np.stack((c * y - s * z, s * y + c * z), axis=-1)
    return profile.distance(local.reshape(-1, 2)).reshape(samples.shape[:2]).max(axis=1)


def barrel_wall_deviation(mesh: TriangleMesh, bore: TwinBore = TwinBore(), order: int = 4) -> np.ndarray:
    """Per barrel wall triangle, the largest distance from its sample points to the exact bores."""
    walls = mesh.kind == TriangleMesh.WALL
    samples = np.einsum("kb,tbd->tkd", _interior_barycentric(order), mesh.corners[walls])
    return bore.distance(samples[..., 1:].reshape(-1, 2)).reshape(samples.shape[:2]).max(axis=1)
