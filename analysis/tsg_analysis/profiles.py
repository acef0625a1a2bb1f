"""Per-element profiles (seed Figs. 9, 10, 12–16): solid fraction, velocity magnitude, longitudinal
velocity and residence time of every screw element, averaged over the steady window.

elements.txt blocks are already time averages over their output interval; a block enters when its
whole interval lies inside the window. Solid fraction is averaged over blocks; the velocities are
weighted by each block's particle mass in the zone (compute element/stats weights by mass within a
block too), so that nearly empty blocks do not weigh like full ones.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .run_files import AnalysisInputError, ElementStatistics, ResidenceRecords, Zones

QUANTITIES = {
    "solid_fraction": "solid fraction (-)",
    "residence_time": "residence time (s)",
    "mean_speed": "velocity magnitude (m/s)",
    "mean_axial_velocity": "longitudinal velocity (m/s)",
}


@dataclass(frozen=True)
class ElementProfile:
    zones: Zones
    values: dict[str, np.ndarray]  # quantity in QUANTITIES -> (zones,), NaN where not measured
    blocks: int  # elements.txt blocks averaged
    records: int  # residence records averaged


def block_mask(stats: ElementStatistics, first_step: float | None) -> np.ndarray:
    """Blocks whose averaging interval starts at or after `first_step` (all when None)."""
    if first_step is None:
        return np.ones(len(stats.timesteps), bool)
    interval = float(np.median(np.diff(stats.timesteps))) if len(stats.timesteps) > 1 else 0.0
    return stats.timesteps - interval >= first_step - 0.5


def average_element_statistics(stats: ElementStatistics, zones: Zones,
                               first_step: float | None) -> tuple[dict[str, np.ndarray], int]:
    if stats.values.shape[1] != len(zones):
        raise AnalysisInputError(f"elements.txt has {stats.values.shape[1]} rows per block but zones.txt "
                                 f"{len(zones)} zones")
    used = block_mask(stats, first_step)
    if not used.any():
        raise AnalysisInputError("elements.txt has no block inside the steady window")
    mass = stats.column("mass")[used]
    weight = mass.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        averages = {
            "solid_fraction": stats.column("solid_fraction")[used].mean(axis=0),
            "mean_speed": np.where(weight > 0, (mass * stats.column("mean_speed")[used]).sum(axis=0) / weight, np.nan),
            "mean_axial_velocity": np.where(
                weight > 0, (mass * stats.column("mean_axial_velocity")[used]).sum(axis=0) / weight, np.nan),
        }
    return averages, int(used.sum())


def zone_residence_times(records: ResidenceRecords, zones: Zones, selected: np.ndarray) -> np.ndarray:
    """Mean time (s) the selected particles spent in each zone."""
    if records.time_by_zone.shape[1] != len(zones):
        raise AnalysisInputError(f"residence.txt has {records.time_by_zone.shape[1]} zone columns but zones.txt "
                                 f"{len(zones)} zones")
    if not selected.any():
        raise AnalysisInputError("no residence records to average per zone")
    return records.time_by_zone[selected].mean(axis=0)


def element_profile(zones: Zones, averages: dict[str, np.ndarray] | None, blocks: int,
                    residence: np.ndarray | None, records: int) -> ElementProfile:
    missing = np.full(len(zones), np.nan)
    values = {name: (averages or {}).get(name, missing) for name in QUANTITIES if name != "residence_time"}
    values["residence_time"] = missing if residence is None else residence
    return ElementProfile(zones, {name: values[name] for name in QUANTITIES}, blocks, records)


def aligned_positions(zone_sets: list[Zones]) -> list[np.ndarray]:
    """Plot positions of each run's zones: runs are aligned on their first kneading element, so a
    periodic sub-domain lines up with the same elements of the full granulator (seed Fig. 9).
    Runs without kneading elements start at position 0."""
    anchors = [zones.kind.index("kneading") if "kneading" in zones.kind else 0 for zones in zone_sets]
    shift = max(anchors)
    return [np.arange(len(zones)) + shift - anchor for zones, anchor in zip(zone_sets, anchors)]
