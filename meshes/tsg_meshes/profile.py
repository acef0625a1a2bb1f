"""Exact two-flight self-wiping screw profile (Booy construction) and the twin-bore barrel section.

Everything here is analytic and in SI units (metres, radians). The profile is described in its own
local frame: tip 0 is centred on the +u axis, angles increase counter-clockwise (u towards v), and the
local frame is mapped to the barrel as (u, v) -> (y, z) rotated by the element phase theta.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

# ConsiGma-1 (seed paper, Tables 1-2)
OUTER_RADIUS = 12.06e-3
ROOT_RADIUS = 6.90e-3
CENTRE_DISTANCE = 19.31e-3
BORE_RADIUS = 12.5e-3
LEAD = 25.0e-3
FLIGHTS = 2
# Clearances of the paper's machine: flight tip to barrel, and tip of one screw to the root of the other
BARREL_CLEARANCE = BORE_RADIUS - OUTER_RADIUS      # 0.44 mm
SCREW_CLEARANCE = CENTRE_DISTANCE - OUTER_RADIUS - ROOT_RADIUS   # 0.35 mm
# Largest clearance of a clearance-scaled machine; the tip angle bounds the screw clearance further
# (tip 1.4 / screw 2.8 mm: r_a 11.1, r_i 5.41 mm, tip angle 6.1 deg; 2.1 / 4.2 mm: 10.4, 4.71 mm, 3.2 deg)
MAX_CLEARANCE = 5e-3
MIN_TIP_ANGLE_DEG = 2.0   # a clearance-scaled profile keeps a tip arc (Booy: KW > 0); 2 deg: a meshable land


@dataclass(frozen=True)
class Arc:
    """Circular arc from angle `start` sweeping `sweep` (signed, radians) about `centre`."""

    centre: tuple[float, float]
    radius: float
    start: float
    sweep: float

    def points(self, parameters: np.ndarray) -> np.ndarray:
        """Points at fractions `parameters` in [0, 1] of the sweep, shape (n, 2)."""
        angles = self.start + self.sweep * np.asarray(parameters, dtype=float)
        return np.column_stack((self.centre[0] + self.radius * np.cos(angles),
                                self.centre[1] + self.radius * np.sin(angles)))

    @property
    def length(self) -> float:
        return abs(self.sweep) * self.radius

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Euclidean distance from each 2-D point to the arc (not to its full circle)."""
        offset = points - np.asarray(self.centre)
        angle_from_start = np.angle(np.exp(1j * (np.arctan2(offset[:, 1], offset[:, 0]) - self.start)))
        # measure along the sweep direction so that "inside the arc" is 0 <= t <= |sweep|
        along = np.mod(angle_from_start * np.sign(self.sweep), 2 * np.pi)
        inside = along <= abs(self.sweep)
        to_circle = np.abs(np.hypot(offset[:, 0], offset[:, 1]) - self.radius)
        ends = self.points(np.array([0.0, 1.0]))
        to_ends = np.min(np.linalg.norm(points[:, None, :] - ends[None, :, :], axis=2), axis=1)
        return np.where(inside, to_circle, to_ends)


@dataclass(frozen=True)
class ScrewProfile:
    """Self-wiping profile with `flights` tips, built for design centre distance r_a + r_i."""

    outer_radius: float = OUTER_RADIUS
    root_radius: float = ROOT_RADIUS
    flights: int = FLIGHTS

    @property
    def design_centre_distance(self) -> float:
        return self.outer_radius + self.root_radius

    @property
    def flank_angle(self) -> float:
        """psi = arccos(a0 / (2 r_a)): angle swept by each flank arc about its centre."""
        return float(np.arccos(self.design_centre_distance / (2 * self.outer_radius)))

    @property
    def tip_angle(self) -> float:
        """KW = pi/Z - 2 psi: angular span of each tip (and each root) arc."""
        return np.pi / self.flights - 2 * self.flank_angle

    @property
    def symmetry_angle(self) -> float:
        """The profile repeats after 2 pi / Z (180 degrees for two flights)."""
        return 2 * np.pi / self.flights

    def area_formula(self) -> float:
        kw, psi, a0, ra, ri = (self.tip_angle, self.flank_angle, self.design_centre_distance,
                               self.outer_radius, self.root_radius)
        return self.flights * (kw * (ra**2 + ri**2) / 2 + a0**2 * psi - a0 * ra * np.sin(psi))

    def perimeter_formula(self) -> float:
        return (self.flights * self.tip_angle * (self.outer_radius + self.root_radius)
                + 2 * self.flights * self.design_centre_distance * self.flank_angle)

    @cached_property
    def sector_arcs(self) -> tuple[Arc, ...]:
        """Arcs of one symmetry sector, counter-clockwise from the start of tip 0:
        tip, flank, root, flank. The other sectors are this one rotated by multiples of 2 pi / Z."""
        kw, ra, ri, a0 = self.tip_angle, self.outer_radius, self.root_radius, self.design_centre_distance
        half_sector = np.pi / self.flights
        tip = Arc((0.0, 0.0), ra, -kw / 2, kw)
        root = Arc((0.0, 0.0), ri, half_sector - kw / 2, kw)
        # A flank is swept by the partner's tip corner; its centre lies diametrically opposite
        # the root corner it ends on, at radius r_a, so |centre - root corner| = r_a + r_i = a0.
        rising = _arc_through(centre_angle=-half_sector - kw / 2, radius=a0, outer_radius=ra,
                              start=tip.points(np.array([1.0]))[0], end=root.points(np.array([0.0]))[0])
        falling = _arc_through(centre_angle=-half_sector + kw / 2, radius=a0, outer_radius=ra,
                               start=root.points(np.array([1.0]))[0],
                               end=ra * np.array([np.cos(2 * half_sector - kw / 2),
                                                  np.sin(2 * half_sector - kw / 2)]))
        return (tip, rising, root, falling)

    def radius(self, phi: np.ndarray) -> np.ndarray:
        """Polar radius r(phi) of the profile (it is star-shaped about its axis)."""
        phi = np.asarray(phi, dtype=float)
        # the profile repeats every 2 pi / Z and is mirror-symmetric about every tip and root axis,
        # so fold phi onto [0, pi / Z], from a tip axis to the next root axis
        folded = np.mod(phi, self.symmetry_angle)
        folded = np.minimum(folded, self.symmetry_angle - folded)
        tip, rising, _, _ = self.sector_arcs
        direction = np.stack((np.cos(folded), np.sin(folded)), axis=-1)
        centre = np.asarray(rising.centre)
        along = direction @ centre
        flank_radius = along + np.sqrt(along**2 + rising.radius**2 - self.outer_radius**2)
        return np.where(folded <= self.tip_angle / 2, self.outer_radius,
                        np.where(folded >= np.pi / self.flights - self.tip_angle / 2,
                                 self.root_radius, flank_radius))

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Distance from 2-D points (local frame) to the exact profile curve."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        best = np.full(len(points), np.inf)
        for sector in range(self.flights):
            turn = sector * self.symmetry_angle
            for arc in self.sector_arcs:
                rotated = Arc(_rotate_point(arc.centre, turn), arc.radius, arc.start + turn, arc.sweep)
                best = np.minimum(best, rotated.distance(points))
        return best


def profile_for_clearance(barrel_clearance: float | None, screw_clearance: float | None = None) -> ScrewProfile:
    """The paper's profile (both None), or one with flight-tip/barrel gap `barrel_clearance` and
    tip/root gap between the screws `screw_clearance` (default: the barrel clearance), in the same
    barrel (bore radius and centre distance unchanged): r_a = R_b - c_barrel and
    r_i = a - r_a - c_screw, so the Booy profile is self-wiping at a - c_screw and the two screws, a
    apart, keep c_screw between them in every axial section (the wiping contact's common normal is
    parallel to the line of centres). In 3D a helical flight's normal leans out of the section, so
    the gap between conveying flights is smaller than c_screw (docs/geometry.md)."""
    if barrel_clearance is None and screw_clearance is None:
        return ScrewProfile()
    if barrel_clearance is None:
        barrel_clearance = BARREL_CLEARANCE
    if screw_clearance is None:
        screw_clearance = barrel_clearance
    for name, value in (("barrel clearance", barrel_clearance), ("screw clearance", screw_clearance)):
        if not 0.0 < value <= MAX_CLEARANCE:
            raise ValueError(f"{name} {value:g} m is outside the allowed range (0, {MAX_CLEARANCE:g}] m")
    outer = BORE_RADIUS - barrel_clearance
    profile = ScrewProfile(outer_radius=outer, root_radius=CENTRE_DISTANCE - outer - screw_clearance)
    if not profile.design_centre_distance < 2 * outer or np.degrees(profile.tip_angle) < MIN_TIP_ANGLE_DEG:
        raise ValueError(f"clearances {barrel_clearance:g} m (barrel) and {screw_clearance:g} m (screw) leave no "
                         f"tip land on the profile (r_a {outer:g} m, r_i {profile.root_radius:g} m): the tip "
                         f"angle must be >= {MIN_TIP_ANGLE_DEG} deg; use a smaller screw clearance")
    return profile


def _rotate_point(point: tuple[float, float], angle: float) -> tuple[float, float]:
    c, s = np.cos(angle), np.sin(angle)
    return (c * point[0] - s * point[1], s * point[0] + c * point[1])


def _arc_through(centre_angle: float, radius: float, outer_radius: float,
                 start: np.ndarray, end: np.ndarray) -> Arc:
    centre = (outer_radius * np.cos(centre_angle), outer_radius * np.sin(centre_angle))
    start_angle = np.arctan2(start[1] - centre[1], start[0] - centre[0])
    end_angle = np.arctan2(end[1] - centre[1], end[0] - centre[0])
    sweep = float(np.angle(np.exp(1j * (end_angle - start_angle))))
    return Arc(centre, radius, float(start_angle), sweep)


@dataclass(frozen=True)
class TwinBore:
    """Two intersecting circular bores of radius `bore_radius`, axes `centre_distance` apart (on y)."""

    bore_radius: float = BORE_RADIUS
    centre_distance: float = CENTRE_DISTANCE

    @property
    def cusp_angle(self) -> float:
        """alpha = arccos(a / (2 R_b)): half-angle, seen from a bore axis, of the cusp opening."""
        return float(np.arccos(self.centre_distance / (2 * self.bore_radius)))

    def area_formula(self) -> float:
        alpha, rb, a = self.cusp_angle, self.bore_radius, self.centre_distance
        return 2 * ((np.pi - alpha) * rb**2 + (a / 2) * rb * np.sin(alpha))

    def perimeter_formula(self) -> float:
        return 2 * 2 * (np.pi - self.cusp_angle) * self.bore_radius

    @cached_property
    def arcs(self) -> tuple[Arc, Arc]:
        """The section boundary, counter-clockwise from the upper cusp: bore 1 (y < 0), then bore 2."""
        alpha, rb, half = self.cusp_angle, self.bore_radius, self.centre_distance / 2
        return (Arc((-half, 0.0), rb, alpha, 2 * np.pi - 2 * alpha),
                Arc((half, 0.0), rb, np.pi + alpha, 2 * np.pi - 2 * alpha))

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Distance from 2-D (y, z) points to the exact twin-bore outline."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        return np.minimum(self.arcs[0].distance(points), self.arcs[1].distance(points))
