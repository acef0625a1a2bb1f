"""Two continuations of one state, compared sample by sample.

A setting run from a kept state of the reference shares the reference's state at its start and the
screws' angle at every instant: over the first part of a window both records carry the same slow
fluctuations of the hold-up and the same forcing by the screws' phase. The difference of two window
means with both windows' intervals (uncertainty.difference) counts that shared part twice; the
difference series D(t) = run(t) − reference(t), sample by sample, cancels it, and its mean's interval
(the one time-series estimator, uncertainty.estimate_mean, over D) is what is left: the two runs'
own divergence. D is not stationary at its very start (it begins at 0 and grows while the runs
decorrelate); its interval is then a little narrow, which the combination over several states
(uncertainty.replica_means, Student's t over the states' mean differences) does not rely on alone.

Per key quantity the series is the one whose plain mean is the window's estimate (Run.key_estimates):
the block values for solid fraction and the domain flux, the ratio estimator's pseudo-values for the
mass-weighted velocities; the sensors' rows for their mass flow. The records are paired by time, not
by step: a run at another time step writes its samples at other times (_aligned).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .massflow import SECONDS_PER_HOUR, row_middles
from .model import DOMAIN_FLUX, MASS_FLOW, SOLID_FRACTION, Key
from .profiles import domain_flux
from .run import ELEMENT_QUANTITIES, Run
from .run_files import AnalysisInputError
from .uncertainty import Estimate, estimate_mean, ratio_pseudo_values, replica_means

Record = tuple[np.ndarray, float, dict[Key, np.ndarray]]  # sample end times (s), sample length (s), series


def key_series(run: Run, start: float, end: float) -> Record:
    """The element blocks of [start, end] (the run's window rule): their end times, their length, and
    per key quantity the per-block series whose mean is the window's estimate of it."""
    used = run.blocks(start, end)
    if used.sum() < 2:
        raise AnalysisInputError(f"{run.path / 'elements.txt'}: fewer than 2 blocks between {start} s and {end} s")
    stats, labels = run.elements, list(run.zones.labels)
    begins, ends = run.block_times
    mass = stats.column("mass")[used]
    series: dict[Key, np.ndarray] = {(MASS_FLOW, DOMAIN_FLUX): domain_flux(stats, run.zones, used) * SECONDS_PER_HOUR}
    for quantity, column in ELEMENT_QUANTITIES:
        values = stats.column(column)[used]
        for zone, label in enumerate(labels):
            series[(quantity, label)] = (values[:, zone] if quantity == SOLID_FRACTION else
                                         ratio_pseudo_values(mass[:, zone] * values[:, zone], mass[:, zone])[1])
    return ends[used], float(np.median(ends - begins)), series


def sensor_series(run: Run, start: float, end: float) -> Record:
    """The mass-flow rows of [start, end] (middle of the row's interval inside, massflow.sensor_flows'
    rule): their end times, their length, and each sensor's flow, kg/h."""
    record = run.massflow
    middle = row_middles(record.time)
    rows = (middle > start) & (middle <= end)
    length = float(np.median(2 * (record.time - middle)))
    return record.time[rows], length, {(MASS_FLOW, name): record.flow[rows, k] for k, name in enumerate(record.sensor_names)}


def _aligned(reference: Record, run: Record, what: str) -> dict[Key, tuple[np.ndarray, np.ndarray]]:
    """The two records on common samples of time. Two continuations of one state at one time step write
    the same samples; at another time step (a time-step study: samples every N steps) one record's
    samples are k times as long, and the shorter ones are averaged over each longer one they tile
    (equal lengths: the mean of their values is the value over the longer interval; for pseudo-values
    it keeps the window's mean). A longer sample not tiled exactly by k shorter ones is left out; an
    error when fewer than 2 are left."""
    length_a, length_b = reference[1], run[1]
    run_is_coarse = length_b > length_a  # coarse: the record with the longer samples
    (ends_c, length_c, coarse), (ends_f, length_f, fine) = (run, reference) if run_is_coarse else (reference, run)
    ratio = length_c / length_f
    per = int(round(ratio))
    tolerance = 0.25 * length_f
    if per < 1 or abs(ratio - per) * length_f > tolerance:
        raise AnalysisInputError(f"{what}: samples of {length_a:.4g} s and {length_b:.4g} s: the longer is not a whole "
                                 "number of the shorter, so they cannot be compared sample by sample")
    keep_c, groups = [], []
    for k, end in enumerate(ends_c):
        inside = np.flatnonzero((ends_f > end - length_c + tolerance) & (ends_f <= end + tolerance))
        if len(inside) == per and abs(ends_f[inside[-1]] - end) <= tolerance:
            keep_c.append(k)
            groups.append(inside)
    if len(keep_c) < 2:
        raise AnalysisInputError(f"the two runs share {len(keep_c)} {what} in the window: not two continuations of one "
                                 "state written at the same times")
    pairs = {}
    for key in coarse:
        if key not in fine:
            continue
        on_coarse = coarse[key][keep_c]
        on_fine = np.array([fine[key][group].mean() for group in groups])
        pairs[key] = (on_fine, on_coarse) if run_is_coarse else (on_coarse, on_fine)
    return pairs


def paired_differences(reference: Run, run: Run, start: float, end: float) -> dict[Key, Estimate]:
    """run − reference over [start, end] per key quantity: the mean of the difference series and its
    95 % interval from the series' own autocorrelation (uncertainty.estimate_mean)."""
    found: dict[Key, Estimate] = {}
    for pairs in (_aligned(key_series(reference, start, end), key_series(run, start, end), "element blocks"),
                  _aligned(sensor_series(reference, start, end), sensor_series(run, start, end), "mass-flow rows")):
        for key, (values_a, values_b) in pairs.items():
            found[key] = estimate_mean(values_b - values_a, detect=False)
    return found


def continued_from(run: Run) -> float:
    """The time a run continues its kept state from (its t_startup: a run from a state starts there)."""
    value = run.parameters.variables.get("t_startup")
    if value is None:
        raise AnalysisInputError(f"{run.path}: no t_startup in its parameters: not a run continued from a state")
    return float(value)


@dataclass(frozen=True)
class PairedRow:
    """One key quantity of a setting against the reference over R states, each compared in its own window."""

    key: Key
    reference: float  # the reference's mean over the R windows
    difference: Estimate  # run − reference, the R states' paired differences as replica means
    per_state: tuple[Estimate, ...]  # each state's paired difference, its interval from its own series
    window_half_width: float  # the widest 95 % half-width of one window on its own (unpaired)
    second_half: float  # the mean paired difference over the windows' second halves

    @property
    def bound(self) -> float:
        """|difference| + half-width, relative to the reference: within a tolerance when this is."""
        return (abs(self.difference.mean) + self.difference.half_width) / abs(self.reference)

    @property
    def state_half_width(self) -> float:
        """The widest 95 % half-width of one state's difference series."""
        return max(d.half_width for d in self.per_state)

    @property
    def states_differing(self) -> int:
        """States whose own paired interval excludes zero (where the true difference is zero, as in a null
        pair, about 1 in 20 at 95 %; more says one state's interval is too narrow)."""
        return sum(abs(d.mean) > d.half_width for d in self.per_state)


def _window_estimates(run: Run, start: float, end: float) -> dict[Key, Estimate]:
    found = dict(run.key_estimates(start, end))
    found.update({(MASS_FLOW, name): e for name, e in run.sensor_flows(start, end).items()})
    return found


def paired_study(reference: Run, runs: Sequence[Run], length: float, skip: float = 0.0) -> list[PairedRow]:
    """Each run continues a state of `reference` (its t_startup) for `length` s, compared from `skip` s after
    its start (0: from the shared state; later leaves out the first part, where the two runs still share
    most of their fluctuation); per key quantity, the paired differences of the states combined with
    uncertainty.replica_means (Student's t over the states, never narrower than the difference series'
    own noise)."""
    if len(runs) < 2:
        raise AnalysisInputError(f"{len(runs)} state(s): a paired interval needs 2 or more")
    if not 0.0 <= skip < length:
        raise AnalysisInputError(f"skip = {skip:g} s is not allowed: 0 <= skip < the window's {length:g} s")
    states = []
    for run in runs:
        begin = continued_from(run)
        start, end = begin + skip, begin + length
        states.append((_window_estimates(reference, start, end), _window_estimates(run, start, end),
                       paired_differences(reference, run, start, end),
                       paired_differences(reference, run, (start + end) / 2, end)))
    rows = []
    for key in states[0][0]:
        if not all(key in own and key in other and key in paired for own, other, paired, _ in states):
            continue
        means = np.array([own[key].mean for own, *_ in states])
        differences = [paired[key] for _, _, paired, _ in states]
        if not abs(means.mean()) > 0 or not all(math.isfinite(d.mean) for d in differences):
            continue
        rows.append(PairedRow(key, float(means.mean()), replica_means(differences), tuple(differences),
                              max(e[key].half_width for own, other, *_ in states for e in (own, other)),
                              float(np.mean([later[key].mean for *_, later in states]))))
    return rows
