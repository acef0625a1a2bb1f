"""Screw surface: the profile polyline swept along x with the element phases, plus the planar faces
that staggered discs expose to each other and, for an inlet-wall domain, the outlet end cap.

numpy does the sweep (rings of profile nodes, quads split along their shorter diagonal); gmsh
discretises the profile arcs and triangulates every planar face (gmsh_engine).
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from .gmsh_engine import chord_angle, discretise_arc_chain, triangulate_polygons
from .profile import CENTRE_DISTANCE, Arc, ScrewProfile
from .spec import HALF_TURN, Element, ScrewConfiguration
from .surface import MeshBuilder, TriangleMesh

# Longest axial edge of an untwisted wall quad, in multiples of the mean profile segment:
# keeps wall triangles of straight prisms above ~18 degrees instead of 6-mm slivers.
MAX_WALL_ASPECT = 3.0


@dataclass(frozen=True)
class ProfilePolyline:
    """Closed profile polygon in the local frame, counter-clockwise, symmetric under the half turn:
    nodes[i + M/2] == -nodes[i] exactly, so rings whose phases differ by 180 degrees coincide."""

    nodes: np.ndarray
    crossing_index: dict[Fraction, int]  # local angle in [0, 180) deg -> node index

    @property
    def size(self) -> int:
        return len(self.nodes)

    def node_at(self, local_angle_deg: Fraction) -> int:
        """Index of the node pinned at a local polar angle (exact, any number of turns)."""
        turns = local_angle_deg % 360
        half_turns = int(turns // HALF_TURN)
        return (self.crossing_index[turns - half_turns * HALF_TURN] + half_turns * self.size // 2) % self.size


def crossing_angles_deg(stagger_deg: Fraction) -> tuple[Fraction, ...]:
    """Local polar angles (mod 180) where a profile and its copy turned by `stagger` intersect.

    The profile is mirror-symmetric about its tip and root axes and r(phi) falls monotonically from
    tip to root, so the two curves cross exactly where they mirror each other: phi = stagger/2 + k 90.
    Seen from the turned copy the same points sit at -stagger/2 + k 90.
    """
    half = stagger_deg / 2
    return tuple(sorted({(s * half + k * 90) % HALF_TURN for s in (1, -1) for k in (0, 1)}))


def sample_profile(profile: ScrewProfile, tolerance: float,
                   staggers_deg: tuple[Fraction, ...]) -> ProfilePolyline:
    """Profile nodes with every chord within `tolerance` of the exact arcs, with nodes pinned at the
    intersection points of all disc staggers used, so the faces between discs share their edges."""
    if profile.flights != 2:
        raise ValueError("the sweep (half-turn ring symmetry, crossing points) is written for two-flight profiles")
    pinned = sorted({angle for stagger in staggers_deg for angle in crossing_angles_deg(stagger)})
    pieces: list[Arc] = []
    pinned_piece: dict[Fraction, int] = {}  # pinned angle -> index of the piece that starts there
    for arc in profile.sector_arcs:
        cuts = sorted((t, angle) for angle in pinned
                      if (t := _fraction_along(arc, profile, angle)) is not None)
        bounds = [0.0, *(t for t, _ in cuts), 1.0]
        for lo, hi, starts_at in zip(bounds, bounds[1:], [None, *(angle for _, angle in cuts)]):
            if starts_at is not None:
                pinned_piece[starts_at] = len(pieces)
            pieces.append(Arc(arc.centre, arc.radius, arc.start + arc.sweep * lo, arc.sweep * (hi - lo)))
    missing = set(pinned) - set(pinned_piece)
    if missing:
        raise ValueError(f"crossing points at {sorted(map(float, missing))} deg fall on no flank arc")
    sector, piece_starts = discretise_arc_chain(pieces, tolerance)
    nodes = np.vstack([sector, -sector])
    return ProfilePolyline(nodes, {angle: int(piece_starts[k]) for angle, k in pinned_piece.items()})


def _fraction_along(arc: Arc, profile: ScrewProfile, angle_deg: Fraction) -> float | None:
    """Where the profile point at polar angle `angle_deg` lies on `arc` (0..1), None if not on it."""
    phi = np.radians(float(angle_deg))
    point = profile.radius(phi) * np.array([np.cos(phi), np.sin(phi)])
    offset = point - np.asarray(arc.centre)
    if abs(np.hypot(*offset) - arc.radius) > 1e-12:
        return None
    t = float(np.angle(np.exp(1j * (np.arctan2(offset[1], offset[0]) - arc.start))) / arc.sweep)
    return t if 1e-9 < t < 1 - 1e-9 else None


@dataclass(frozen=True)
class ScrewPlacement:
    """Where a screw sits: axis at (y, 0), phase added to screw 1's phases (screw 2: 180/Z deg)."""

    axis_y: float
    phase_offset_deg: Fraction

    @staticmethod
    def of(screw: int, profile: ScrewProfile = ScrewProfile()) -> "ScrewPlacement":
        if screw not in (1, 2):
            raise ValueError(f"screw must be 1 or 2, got {screw}")
        sign = -1 if screw == 1 else 1
        return ScrewPlacement(sign * CENTRE_DISTANCE / 2, Fraction(0) if screw == 1 else HALF_TURN / profile.flights)


@dataclass(frozen=True)
class _Ring:
    """The last axial ring swept: its vertex ids, phase (deg) and absolute (M, 3) points."""

    ids: np.ndarray
    phase: Fraction
    points: np.ndarray


class _ScrewSweep:
    """Builds one screw: rings of vertex ids per axial plane, walls between them, faces at jumps."""

    def __init__(self, polyline: ProfilePolyline, placement: ScrewPlacement, tolerance: float,
                 profile: ScrewProfile, disc_gap_mm: Fraction = Fraction(0)) -> None:
        self.polyline = polyline
        self.disc_gap_mm = disc_gap_mm
        self.placement = placement
        self.profile = profile
        self.helix_step = chord_angle(profile.outer_radius, tolerance)
        segment = np.linalg.norm(np.roll(polyline.nodes, -1, axis=0) - polyline.nodes, axis=1)
        self.max_wall_height = MAX_WALL_ASPECT * float(segment.mean())
        self.builder = MeshBuilder()
        self.last_ring: _Ring | None = None  # None until the first element is added

    def ring(self, x_mm: Fraction, phase_deg: Fraction) -> np.ndarray:
        """Absolute (M, 3) ring positions; phases equal mod 180 deg give bit-identical point sets."""
        phase = phase_deg + self.placement.phase_offset_deg
        half_turns = int(phase // HALF_TURN)
        angle = np.radians(float(phase - half_turns * HALF_TURN))
        c, s = np.cos(angle), np.sin(angle)
        local = self.polyline.nodes
        turned = np.column_stack((c * local[:, 0] - s * local[:, 1], s * local[:, 0] + c * local[:, 1]))
        m = self.polyline.size
        turned = turned[(np.arange(m) + half_turns * m // 2) % m]
        return np.column_stack((np.full(m, float(x_mm) / 1000), turned[:, 0] + self.placement.axis_y, turned[:, 1]))

    def planes(self, element: Element, start_mm: Fraction) -> list[tuple[Fraction, Fraction]]:
        """(x, phase) of the axial planes of an element from `start_mm` (its start, or the end of a
        spacer): twisted elements are cut so that a tip point turns at most the helix step per
        plane, straight ones by the wall aspect limit."""
        length = element.x_end_mm - start_mm
        if element.twisted:
            if start_mm != element.x_start_mm:
                raise ValueError(f"element {element.index}: a spacer before a twisted element is not supported")
            turn = abs(np.radians(float(element.phase_end_deg - element.phase_start_deg)))
            count = int(np.ceil(turn / self.helix_step))
        else:
            if length <= 0:
                raise ValueError(f"element {element.index}: disc gap {float(self.disc_gap_mm)} mm is not shorter "
                                 f"than the disc ({float(element.length_mm)} mm)")
            count = int(np.ceil(float(length) / 1000 / self.max_wall_height))
        return [(start_mm + length * Fraction(k, count),
                 element.phase_start_deg + (element.phase_end_deg - element.phase_start_deg) * Fraction(k, count))
                for k in range(count + 1)]

    def add_element(self, element: Element) -> None:
        previous = self.last_ring
        jump = previous is not None and (element.phase_start_deg - previous.phase) % HALF_TURN != 0
        start_mm = element.x_start_mm + (self.disc_gap_mm if jump else 0)
        for k, (x_mm, phase) in enumerate(self.planes(element, start_mm)):
            points = self.ring(x_mm, phase)
            if k == 0 and previous is not None:
                ids = self._continue_ring(previous, element.x_start_mm, phase, points, element.index)
            else:
                ids = self.builder.add_vertices(points)
                if previous is not None:  # k > 0: this element's earlier plane
                    self._add_wall(previous.ids, ids, previous.points, points, element.index)
            previous = _Ring(ids, phase, points)
        self.last_ring = previous

    def _continue_ring(self, previous: _Ring, x_mm: Fraction, phase: Fraction, points: np.ndarray,
                       part: int) -> np.ndarray:
        """First ring of an element: the previous ring itself when the phase is unchanged mod 180,
        otherwise a new ring that shares the crossing nodes, plus the faces between the two."""
        jump = phase - previous.phase
        m = self.polyline.size
        if jump % HALF_TURN == 0:
            return previous.ids[(np.arange(m) + int(jump // HALF_TURN) * m // 2) % m]
        # the two profiles cross at upstream-local angles jump/2 + k 90 (crossing_angles_deg)
        crossings = [(jump % HALF_TURN) / 2 + 90 * k for k in range(4)]
        upstream_at = [self.polyline.node_at(angle) for angle in crossings]
        downstream_at = [self.polyline.node_at(angle - jump) for angle in crossings]
        outside = [bool(self.profile.radius(np.radians(float(crossings[k]) + 45))
                        > self.profile.radius(np.radians(float(crossings[k]) + 45 - float(jump)))) for k in range(4)]
        if self.disc_gap_mm:
            return self._spacer(previous, x_mm, phase, upstream_at, downstream_at, outside, part)
        fresh = np.ones(m, dtype=bool)
        fresh[downstream_at] = False
        ids = np.empty(m, dtype=np.int64)
        ids[fresh] = self.builder.add_vertices(points[fresh])
        ids[downstream_at] = previous.ids[upstream_at]
        upstream = (previous.ids, previous.points, upstream_at)
        downstream = (ids, points, downstream_at)
        polygons, labels, facing = [], [], []
        for k in range(4):
            # between crossings k and k + 1 one ring lies outside the other and bounds the face:
            # the upstream disc's end shows (+x) where it is outside, the downstream's start (-x)
            upstream_outside = outside[k]
            (outer_ids, outer_points, outer_at), (inner_ids, inner_points, inner_at) = (
                (upstream, downstream) if upstream_outside else (downstream, upstream))
            outer = _walk(outer_at[k], outer_at[(k + 1) % 4], m)
            inner = _walk(inner_at[k], inner_at[(k + 1) % 4], m)[-2:0:-1]  # back, without the shared ends
            polygons.append(np.vstack([outer_points[outer, 1:], inner_points[inner, 1:]]))
            labels.append(np.concatenate([outer_ids[outer], inner_ids[inner]]))
            facing.append(1 if upstream_outside else -1)
        self._add_planar(float(x_mm) / 1000, polygons, labels, facing, part)
        return ids

    def _spacer(self, previous: _Ring, x_mm: Fraction, phase: Fraction, upstream_at: list[int],
                downstream_at: list[int], upstream_outside: list[bool], part: int) -> np.ndarray:
        """A phase jump opened into a spacer of length disc_gap_mm: the upstream disc ends at x_mm
        with the faces where it lies outside the downstream profile; from x_mm to x_mm + gap the
        section is the intersection of the two profiles; the downstream disc starts there with the
        faces where it lies outside the upstream profile. So the two screws' disc faces that meet
        at a jump (screw 1's disc k, screw 2's disc k + 1: they overlap in projection) are the gap
        apart instead of sliding past each other in one plane. Returns the downstream ring's ids
        (its points are self.ring(x_mm + gap, phase))."""
        m = self.polyline.size
        x1, x2 = float(x_mm) / 1000, float(x_mm + self.disc_gap_mm) / 1000
        up_ids, up_points = previous.ids, previous.points
        down_x1 = self.ring(x_mm, phase)
        down_x2 = self.ring(x_mm + self.disc_gap_mm, phase)
        walks_up = [_walk(upstream_at[k], upstream_at[(k + 1) % 4], m) for k in range(4)]
        walks_down = [_walk(downstream_at[k], downstream_at[(k + 1) % 4], m) for k in range(4)]
        # intersection outline at x1: per quadrant the inner profile, crossing k included, k + 1 not
        segments_ids, segments_points = [], []
        polygons, labels = [], []
        for k in range(4):
            if not upstream_outside[k]:
                nodes = walks_up[k][:-1]
                segments_ids.append(up_ids[nodes])
                segments_points.append(up_points[nodes])
                continue
            interior = walks_down[k][1:-1]
            fresh = self.builder.add_vertices(down_x1[interior])
            segments_ids.append(np.concatenate([[up_ids[upstream_at[k]]], fresh]))
            segments_points.append(np.vstack([up_points[upstream_at[k]][None], down_x1[interior]]))
            polygons.append(np.vstack([up_points[walks_up[k], 1:], down_x1[interior][::-1, 1:]]))
            labels.append(np.concatenate([up_ids[walks_up[k]], fresh[::-1]]))
        self._add_planar(x1, polygons, labels, [1] * len(polygons), part)
        inner_x1_ids, inner_x1 = np.concatenate(segments_ids), np.vstack(segments_points)
        inner_x2 = inner_x1.copy()
        inner_x2[:, 0] = x2
        inner_x2_ids = self.builder.add_vertices(inner_x2)
        self._add_wall(inner_x1_ids, inner_x2_ids, inner_x1, inner_x2, part)
        # the downstream ring at x2 shares the outline's nodes where it is the inner profile
        ids = np.full(m, -1, dtype=np.int64)
        first = np.cumsum([0] + [len(segment) for segment in segments_ids])
        pending = []
        for k in range(4):
            outline = inner_x2_ids[first[k]:first[k + 1]]
            ids[walks_down[k][0]] = outline[0]
            if upstream_outside[k]:
                ids[walks_down[k][:-1]] = outline
            else:
                ids[walks_down[k][1:-1]] = self.builder.add_vertices(down_x2[walks_down[k][1:-1]])
                pending.append((k, outline, inner_x2[first[k]:first[k + 1]]))
        polygons, labels = [], []
        for k, outline, outline_points in pending:
            polygons.append(np.vstack([down_x2[walks_down[k], 1:], outline_points[1:][::-1, 1:]]))
            labels.append(np.concatenate([ids[walks_down[k]], outline[1:][::-1]]))
        self._add_planar(x2, polygons, labels, [-1] * len(polygons), part)
        return ids

    def _add_planar(self, x: float, polygons: list[np.ndarray], labels: list[np.ndarray],
                    facing: list[int], part: int) -> None:
        """Triangulate planar polygons at x with gmsh; facing +1: normal +x, -1: normal -x."""
        interior, triangles, owner = triangulate_polygons(polygons, labels)
        interior_ids = self.builder.add_vertices(np.column_stack((np.full(len(interior), x), interior)))
        ids = np.where(triangles >= 0, triangles, interior_ids[np.maximum(-1 - triangles, 0)])
        # gmsh's triangles are counter-clockwise in (y, z), i.e. their normal is +x
        backwards = np.asarray(facing)[owner] < 0
        ids[backwards] = ids[backwards][:, ::-1]
        self.builder.add_triangles(ids, part, TriangleMesh.PLANE)

    def _add_wall(self, ids_a: np.ndarray, ids_b: np.ndarray, points_a: np.ndarray, points_b: np.ndarray,
                  part: int) -> None:
        """Quads between consecutive rings, split along the shorter diagonal (smaller deviation on
        the helix); corner order makes the normal point out of the screw."""
        nxt = np.roll(np.arange(len(ids_a)), -1)
        p0, p1, p2, p3 = points_a, points_a[nxt], points_b[nxt], points_b
        q0, q1, q2, q3 = ids_a, ids_a[nxt], ids_b[nxt], ids_b
        short_02 = np.linalg.norm(p2 - p0, axis=1) <= np.linalg.norm(p3 - p1, axis=1)
        first = np.where(short_02[:, None], np.column_stack((q0, q1, q2)), np.column_stack((q0, q1, q3)))
        second = np.where(short_02[:, None], np.column_stack((q0, q2, q3)), np.column_stack((q1, q2, q3)))
        self.builder.add_triangles(np.stack((first, second), axis=1).reshape(-1, 3), part, TriangleMesh.WALL)

    def cap(self, x_mm: Fraction, part: int) -> None:
        """Flat end face over the whole last ring, facing +x (the outlet)."""
        if self.last_ring is None:
            raise ValueError("a screw end cap needs at least one element before it")
        self._add_planar(float(x_mm) / 1000, [self.last_ring.points[:, 1:]], [self.last_ring.ids], [1], part)


def _walk(start: int, stop: int, size: int) -> np.ndarray:
    """Node indices from `start` forward (counter-clockwise) to `stop`, both included, round a ring."""
    return (start + np.arange((stop - start) % size + 1)) % size


def build_screw(configuration: ScrewConfiguration, polyline: ProfilePolyline, screw: int,
                tolerance: float, profile: ScrewProfile = ScrewProfile(), disc_gap: float = 0.0) -> TriangleMesh:
    """Surface of screw 1 or 2. Periodic domains: open at both ends. Inlet-wall domains: open at
    x = 0 (the barrel's inlet wall covers it) and capped at the outlet. disc_gap (m): a spacer of
    that length, with the section common to both discs, at every phase jump between discs."""
    gap_mm = Fraction(str(round(disc_gap * 1e3, 9)))
    sweep = _ScrewSweep(polyline, ScrewPlacement.of(screw, profile), tolerance, profile, gap_mm)
    for element in configuration.elements:
        sweep.add_element(element)
    if configuration.ends == "inlet-wall":
        last = configuration.elements[-1]
        sweep.cap(last.x_end_mm, last.index)
    return sweep.builder.build()
