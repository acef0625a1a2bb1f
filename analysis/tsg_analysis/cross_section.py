"""Time-averaged solid-fraction maps of the barrel cross-section (seed Fig. 7).

Each particle's volume is put into the y–z bin that holds its centre, for particles whose x lies in
the elements of one type; the sum is divided by the bin volume (bin area × total axial length of
those elements) and by the number of frames. The denominator is the whole bin, screw included:
bins the screw sweeps through carry less material on average, as in the paper's maps. Bins should
be no smaller than a particle diameter, or single particles show up as speckle.
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from tsg_meshes.machine import BORE_RADIUS, CENTRE_DISTANCE  # the machine geometry's one source

from .dumps import ParticleFrame
from .run_files import AnalysisInputError

DEFAULT_BIN_SIZE = 0.5e-3  # m: ≈ 1.25 reference particle diameters (400 μm)


@dataclass(frozen=True)
class SolidFractionMap:
    kind: str
    y_edges: np.ndarray  # m
    z_edges: np.ndarray  # m
    solid_fraction: np.ndarray  # (y bins, z bins), NaN outside the twin bore
    axial_length: float  # m of screw the map averages over
    frames: int

    @property
    def mean(self) -> float:
        """Mean over the bins inside the bore."""
        return float(np.nanmean(self.solid_fraction))


def grid_edges(bin_size: float, centre_distance: float = CENTRE_DISTANCE,
               bore_radius: float = BORE_RADIUS) -> tuple[np.ndarray, np.ndarray]:
    """Bin edges covering the twin bore; bins are centred on the screw axes' plane z = 0."""
    half_y = centre_distance / 2 + bore_radius
    ny = int(np.ceil(2 * half_y / bin_size))
    nz = int(np.ceil(2 * bore_radius / bin_size))
    return (np.arange(ny + 1) - ny / 2) * bin_size, (np.arange(nz + 1) - nz / 2) * bin_size


def inside_bore(y: np.ndarray, z: np.ndarray, centre_distance: float = CENTRE_DISTANCE,
                bore_radius: float = BORE_RADIUS) -> np.ndarray:
    half = centre_distance / 2
    return (np.hypot(y + half, z) <= bore_radius) | (np.hypot(y - half, z) <= bore_radius)


class SolidFractionAccumulator:
    """Sums particle volume per y–z bin for each element type, one frame at a time (dumps are big)."""

    def __init__(self, ranges_by_kind: dict[str, list[tuple[float, float]]], bin_size: float = DEFAULT_BIN_SIZE,
                 centre_distance: float = CENTRE_DISTANCE, bore_radius: float = BORE_RADIUS) -> None:
        self.ranges_by_kind = ranges_by_kind
        self.bin_size = bin_size
        self.centre_distance, self.bore_radius = centre_distance, bore_radius
        self.y_edges, self.z_edges = grid_edges(bin_size, centre_distance, bore_radius)
        self.volume = {kind: np.zeros((len(self.y_edges) - 1, len(self.z_edges) - 1)) for kind in ranges_by_kind}
        self.frames = 0

    def add(self, frame: ParticleFrame) -> None:
        frame.require("x", "y", "z", "radius")
        x = frame.columns["x"]
        particle_volume = frame.volume
        for kind, ranges in self.ranges_by_kind.items():
            selected = np.zeros(len(x), bool)
            for low, high in ranges:
                selected |= (x >= low) & (x < high)
            counts, _, _ = np.histogram2d(frame.columns["y"][selected], frame.columns["z"][selected],
                                          bins=(self.y_edges, self.z_edges), weights=particle_volume[selected])
            self.volume[kind] += counts
        self.frames += 1

    def maps(self) -> dict[str, SolidFractionMap]:
        if self.frames == 0:
            raise AnalysisInputError("no dump frames to average")
        y_mid, z_mid = np.meshgrid(0.5 * (self.y_edges[1:] + self.y_edges[:-1]),
                                   0.5 * (self.z_edges[1:] + self.z_edges[:-1]), indexing="ij")
        outside = ~inside_bore(y_mid, z_mid, self.centre_distance, self.bore_radius)
        maps = {}
        for kind, ranges in self.ranges_by_kind.items():
            length = sum(high - low for low, high in ranges)
            fraction = self.volume[kind] / (self.bin_size**2 * length * self.frames)
            fraction[outside] = np.nan
            maps[kind] = SolidFractionMap(kind, self.y_edges, self.z_edges, fraction, length, self.frames)
        return maps


def solid_fraction_maps(frames: Iterable[ParticleFrame], ranges_by_kind: dict[str, list[tuple[float, float]]],
                        bin_size: float = DEFAULT_BIN_SIZE, centre_distance: float = CENTRE_DISTANCE,
                        bore_radius: float = BORE_RADIUS) -> dict[str, SolidFractionMap]:
    """One map per element type from a sequence of frames."""
    accumulator = SolidFractionAccumulator(ranges_by_kind, bin_size, centre_distance, bore_radius)
    for frame in frames:
        accumulator.add(frame)
    return accumulator.maps()
