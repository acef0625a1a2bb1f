"""Per-element profiles (seed Figs. 9, 10, 12–16): solid fraction, velocity magnitude, longitudinal
velocity and residence time of every screw element, averaged over the steady window.

elements.txt blocks are already time averages over their output interval; a block enters when its
whole interval lies inside the window. Solid fraction is averaged over blocks; the velocities are
weighted by each block's particle mass in the zone (compute element/stats weights by mass within a
block too), so that nearly empty blocks do not weigh like full ones. This is the one mass-weighted
per-element average of the project; every value comes with its 95 % interval (uncertainty.py).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .massflow import SECONDS_PER_HOUR
from .run_files import AnalysisInputError, ElementStatistics, ResidenceRecords, Zones
from .uncertainty import Estimate, estimate_mean, estimate_ratio

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
    estimates: dict[str, list[Estimate]]  # quantity -> per zone mean ± 95 % interval (measured quantities only)


def block_mask(stats: ElementStatistics, first_step: float | None, last_step: float | None = None) -> np.ndarray:
    """Blocks whose whole averaging interval lies in [first_step, last_step] (a bound None: open),
    with half a step of slack (the window rule of run.Run)."""
    steps = stats.timesteps
    interval = float(np.median(np.diff(steps))) if len(steps) > 1 else 0.0
    inside = np.ones(len(steps), bool)
    if first_step is not None:
        inside &= steps - interval >= first_step - 0.5
    if last_step is not None:
        inside &= steps <= last_step + 0.5
    return inside


def element_estimates(stats: ElementStatistics, zones: Zones, used: np.ndarray,
                      times: np.ndarray | None = None) -> tuple[dict[str, list[Estimate]], np.ndarray]:
    """Per zone: solid fraction (block mean) and mass-weighted velocities Σ m v / Σ m over the blocks
    `used` (block_mask), each ± 95 % interval; `times` (s, one per block) for start-up detection.
    Returns the estimates and the mask of blocks used."""
    if stats.values.shape[1] != len(zones):
        raise AnalysisInputError(f"elements.txt has {stats.values.shape[1]} rows per block but zones.txt "
                                 f"{len(zones)} zones")
    if not used.any():
        raise AnalysisInputError("elements.txt has no block inside the steady window")
    block_times = (np.asarray(times, dtype=np.float64) if times is not None else stats.timesteps.astype(float))[used]
    mass = stats.column("mass")[used]
    estimates: dict[str, list[Estimate]] = {
        "solid_fraction": [estimate_mean(column, block_times, float(block_times[0]))
                           for column in stats.column("solid_fraction")[used].T]}
    for name in ("mean_speed", "mean_axial_velocity"):
        velocity = stats.column(name)[used]
        estimates[name] = [estimate_ratio(m * v, m, block_times, float(block_times[0]))
                           for m, v in zip(mass.T, velocity.T)]
    return estimates, used


def zone_residence_times(records: ResidenceRecords, zones: Zones, selected: np.ndarray) -> list[Estimate]:
    """Mean time (s) the selected particles spent in each zone ± 95 % interval (records in exit order)."""
    if records.time_by_zone.shape[1] != len(zones):
        raise AnalysisInputError(f"residence.txt has {records.time_by_zone.shape[1]} zone columns but zones.txt "
                                 f"{len(zones)} zones")
    if not selected.any():
        raise AnalysisInputError("no residence records to average per zone")
    order = np.argsort(records.exit_time[selected], kind="stable")
    return [estimate_mean(column[order], detect=False) for column in records.time_by_zone[selected].T]


def element_profile(zones: Zones, estimates: dict[str, list[Estimate]], blocks: int, records: int) -> ElementProfile:
    """`estimates`: quantity -> one Estimate per zone, for the quantities that were measured."""
    values = {name: np.array([e.mean for e in estimates[name]]) if name in estimates else np.full(len(zones), np.nan)
              for name in QUANTITIES}
    return ElementProfile(zones, values, blocks, records, estimates)


def aligned_positions(zone_sets: list[Zones]) -> list[np.ndarray]:
    """Plot positions of each run's zones: runs are aligned on their first kneading element, so a
    periodic sub-domain lines up with the same elements of the full granulator (seed Fig. 9).
    Runs without kneading elements start at position 0."""
    anchors = [zones.kind.index("kneading") if "kneading" in zones.kind else 0 for zones in zone_sets]
    shift = max(anchors)
    return [np.arange(len(zones)) + shift - anchor for zones, anchor in zip(zone_sets, anchors)]


def domain_flux(stats: ElementStatistics, zones: Zones, used: np.ndarray) -> np.ndarray:
    """Σ_e m_e v_x,e / L per block, kg/s: the mass flow averaged over every plane of the zones."""
    length = float(np.sum(zones.x_end - zones.x_start))
    return (stats.column("mass")[used] * stats.column("mean_axial_velocity")[used]).sum(axis=1) / length


def domain_throughput(stats: ElementStatistics, zones: Zones, used: np.ndarray, times: np.ndarray) -> Estimate:
    """Mass flow through the domain, kg/h: the flux averaged over every plane (converges faster
    than a single sensor plane), ± 95 % interval."""
    return estimate_mean(domain_flux(stats, zones, used) * SECONDS_PER_HOUR, times[used], float(times[used][0]))


def holdup_residence(stats: ElementStatistics, zones: Zones, used: np.ndarray,
                     times: np.ndarray) -> dict[str, Estimate]:
    """Residence time per element type from hold-up over throughput (Little's law at steady state):
    τ_type = ⟨Σ_{e ∈ type} m_e⟩ / ⟨Q⟩ with Q = Σ_e m_e v_x,e / L the domain flux, s, ± 95 % interval
    (ratio estimator). Not available (NaN) when the mean flux is not forward."""
    mass = stats.column("mass")[used]
    flux = domain_flux(stats, zones, used)
    kinds = np.asarray(zones.kind)
    holdups = {kind: mass[:, kinds == kind].sum(axis=1) for kind in zones.types_present}
    holdups["total"] = mass.sum(axis=1)
    block_times = times[used]
    return {kind: estimate_ratio(holdup, flux, block_times, float(block_times[0])) for kind, holdup in holdups.items()}


def element_holdup_residence(stats: ElementStatistics, zones: Zones, used: np.ndarray,
                             times: np.ndarray) -> list[Estimate]:
    """Residence time of each element from its hold-up over the domain flux (Little's law at steady
    state, as holdup_residence per type): τ_e = ⟨m_e⟩ / ⟨Q⟩, s, ± 95 % interval, one per zone."""
    mass = stats.column("mass")[used]
    flux = domain_flux(stats, zones, used)
    block_times = times[used]
    return [estimate_ratio(mass[:, e], flux, block_times, float(block_times[0])) for e in range(len(zones))]
