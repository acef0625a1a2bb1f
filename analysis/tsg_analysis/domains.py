"""The periodic sub-domain against the full granulator (seed paper Section 3.1, Figs. 8–9).

The paper runs the full granulator to steady state, gives the periodic sub-domain (conveying, one
6 × 60° kneading block, conveying) the hold-up the full run has on the same elements, and compares
the two element by element. Here:

- `section_holdup`: the mass the full run holds on the elements the periodic domain models, aligned
  on the first kneading element (Zones.aligned_labels). The periodic domain's conveying ends are
  shorter than the full machine's conveying elements around the block (29.2 against 37.5 mm): their
  mass is taken in proportion to length, i.e. as uniformly filled along each such element.
- `compare_domains`: each quantity of the periodic runs (replicas combined) against the full run's
  on the aligned elements, difference ± 95 % interval: solid fraction, speed, axial velocity; the
  mass flow through the section (Σ m v_x over the aligned elements / their length) against the
  periodic domain flux; the mean time per passage of each element, of the kneading block and of the
  section two ways; and the distributions of the time per passage of the kneading block and of the
  section (Kolmogorov–Smirnov distance, the Fig. 8 analogue).
- Time per passage, always over the periodic domain's element lengths (the full machine's longer
  conveying elements count in proportion to length, as for the hold-up):
  - by mass balance, hold-up / net flux = L Σ m / Σ m v_x (Little's law; time-series ratio), from
    the element statistics, available whenever the net flux is forward;
  - from the residence records, as passes that end in a steady window: the distribution of the
    times of the passes that end in a window of stationary flow is the distribution of the time per
    passage, provided every pass that ends in the window is known and began after the flow became
    stationary. A periodic run's record is written when its pass of the domain completes; its
    passes count from RECORD_HORIZON balance times of the section after the first recorded entry
    on (the fill starts every pass at once: earlier, only the fast ones have completed). A full
    run's record is written when the particle leaves the machine, long after it left the section:
    its passes of the section come from the outlet records together with the snapshot of the
    particles still inside at the end (`full_passes`; the case's `-v inside_records 1`), and count
    from RECORD_HORIZON balance times of the section after its steady start on. A run without such
    passes is reported with the reason, not estimated.
- `machine_residence`: the full granulator's mean residence time two ways — the mean over the outlet
  records of the window, and the mass balance τ = M / ṁ (hold-up over throughput; Little's law, exact
  for any steady flow). The records lag: a particle leaving early in the window entered about τ
  before, so the two agree only once the window starts at least τ after the start of steady flow.
Every run is taken from its steady start on (given, or detected as in validation.steady_start).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .massflow import SECONDS_PER_HOUR
from .model import AXIAL_VELOCITY, DOMAIN_FLUX, MASS_FLOW, SOLID_FRACTION, SPEED
from .rtd import AGREEMENT_KS_DISTANCE, MIN_RECORDS, RTDComparison, compare_rtds, mean_residence
from .run import Run
from .run_files import AnalysisInputError, Zones
from .uncertainty import (
    MIN_INDEPENDENT,
    Difference,
    Estimate,
    combine_replicas,
    detect_start,
    difference,
    estimate_mean,
    estimate_ratio,
    format_interval,
    statistical_inefficiency,
)

TIME_PER_PASSAGE = "time per passage"                 # from the residence records
TIME_BY_BALANCE = "time per passage, hold-up / flux"  # Little's law on the element statistics
RECORD_HORIZON = 3.0  # record times after the first entry; a Gamma(2)-distributed time exceeds 3 means with 1.7 %
SECTION_FLUX = "flux through the section Σ m v_x / L"
KNEADING_BLOCK = "kneading block"
CONVEYING = "conveying elements"
SECTION = "section"
RTD_SCOPES = (CONVEYING, KNEADING_BLOCK, SECTION)   # seed Fig. 8: by element type, and the whole domain


@dataclass(frozen=True)
class DomainRow:
    quantity: str
    scope: str
    full: Estimate
    periodic: Estimate
    difference: Difference  # periodic − full


def section_indices(full: Zones, periodic: Zones) -> list[int]:
    """For each periodic zone, the index of the full run's zone it stands for."""
    labels = full.aligned_labels(periodic)
    found = {label: i for i, label in enumerate(labels) if label is not None}
    missing = [label for label in periodic.labels if label not in found]
    if missing:
        raise AnalysisInputError(f"the full run's zones have no counterpart of the periodic domain's {', '.join(missing)} "
                                 "(aligned on the first kneading element)")
    return [found[label] for label in periodic.labels]


def _steady_blocks(run: Run, start: float | None) -> tuple[np.ndarray, np.ndarray]:
    """The element blocks from `start` s on (all when None) and their end times, s."""
    used = run.blocks(start)
    if used.sum() < 2:
        raise AnalysisInputError(f"{run.path}: fewer than 2 element blocks from {start or 0} s")
    return used, run.block_times[1][used]


FILLING_WITHIN = 0.75   # a filling run's steady window keeps at least the last quarter of its record


def filling_steady_start(holdup: np.ndarray, flux: np.ndarray, times: np.ndarray,
                         min_independent: float = MIN_INDEPENDENT) -> float:
    """When a run that fills from empty has become steady (s): the later of the starts of
    stationarity of its hold-up and of its flux (uncertainty.detect_start with the origin in the
    first FILLING_WITHIN of the record: the filling may take more than half of it, and a window of
    the last few samples of a record that is still filling would look steady to the drift test). Raises ValueError when the window from
    there keeps fewer than `min_independent` independent samples of the hold-up, or when the hold-up's
    two halves of that window differ (uncertainty's drift test), so that a run still filling, or only
    just steady, is refused rather than averaged over its filling."""
    holdup_start = detect_start(holdup, times, within=FILLING_WITHIN)
    flux_start = detect_start(flux, times, within=FILLING_WITHIN)
    if holdup_start is None or flux_start is None:
        raise ValueError(f"{len(times)} element blocks: too short a record to detect a steady state")
    start = max(holdup_start, flux_start)
    window = np.asarray(holdup)[np.asarray(times) >= start]
    independent = len(window) / statistical_inefficiency(window) if len(window) > 1 else 0.0
    if not independent >= min_independent:
        raise ValueError(f"the hold-up is stationary from t = {holdup_start:.4g} s and the flux from {flux_start:.4g} s, "
                         f"which leaves {independent:.1f} independent samples of the hold-up to the end of the record "
                         f"(t = {float(times[-1]):.4g} s; {min_independent:g} needed): run it longer, or give the "
                         "start by hand")
    drift = estimate_mean(window).drift
    if drift is not False:
        halves = np.array_split(window, 2)
        raise ValueError(f"the hold-up from t = {start:.4g} s to the end of the record (t = {float(times[-1]):.4g} s) "
                         + ("still changes: " if drift else "cannot be shown to be steady: ")
                         + f"{float(halves[0].mean()):.4g} in its first half, {float(halves[1].mean()):.4g} in its "
                         "second: run it longer, or give the start by hand")
    return start


def full_steady_start(full_run: Run, periodic: Zones) -> float:
    """The full run's steady start on the periodic domain's section: filling_steady_start of the
    section's hold-up and flux (AnalysisInputError naming the run when there is none yet)."""
    full = full_run.zones
    index = section_indices(full, periodic)
    stats = full_run.elements
    used, times = _steady_blocks(full_run, None)
    mass = stats.column("mass")[used][:, index]
    share = (periodic.x_end - periodic.x_start) / (full.x_end - full.x_start)[index]
    momentum = mass * stats.column("mean_axial_velocity")[used][:, index]
    try:
        return filling_steady_start((mass * share).sum(axis=1), momentum.sum(axis=1), times, MIN_INDEPENDENT)
    except ValueError as problem:
        raise AnalysisInputError(f"{full_run.path}: no steady window on the periodic domain's section: {problem}") from None


def section_holdup(full_run: Run, periodic: Zones, start: float) -> Estimate:
    """Mass (kg) the full run holds on the periodic domain's elements from `start` s on, ± 95 %."""
    full = full_run.zones
    index = section_indices(full, periodic)
    stats = full_run.elements
    used, times = _steady_blocks(full_run, start)
    mass = stats.column("mass")[used]
    full_length = full.x_end - full.x_start
    share = (periodic.x_end - periodic.x_start) / full_length[index]
    return estimate_mean((mass[:, index] * share).sum(axis=1), times, float(times[0]))


def _section_flux(full_run: Run, periodic: Zones, start: float) -> Estimate:
    full = full_run.zones
    index = section_indices(full, periodic)
    stats = full_run.elements
    used, times = _steady_blocks(full_run, start)
    momentum = (stats.column("mass")[used] * stats.column("mean_axial_velocity")[used])[:, index]
    length = float(np.sum((full.x_end - full.x_start)[index]))
    return estimate_mean(momentum.sum(axis=1) / length * SECONDS_PER_HOUR, times, float(times[0]))


def passage_times(run: Run, zone_indices: Sequence[int], start: float, weights: np.ndarray | None = None,
                  horizon: float = 0.0) -> np.ndarray:
    """Per complete record ending after `start` s (outlet or periodic pass) and at least `horizon` s
    after the first recorded entry, the time spent in the given zones together (s; each zone's time
    times its weight), in exit order."""
    records = run.residence
    if not len(records.exit_time):
        return np.zeros(0)
    origin = float(records.entry_time.min())
    complete = run.records(start) & (records.exit_time >= origin + horizon)
    order = np.argsort(records.exit_time[complete], kind="stable")
    chosen = records.time_by_zone[complete][:, list(zone_indices)]
    scale = np.ones(len(zone_indices)) if weights is None else np.asarray(weights, dtype=float)
    return (chosen @ scale)[order]


def counted_lengths(zones: Zones, periodic_runs: Sequence[Run]) -> np.ndarray:
    """Per periodic zone, the length inside the runs' analysis domain (their records' header; m)."""
    domains = {run.residence.analysis_domain for run in periodic_runs}
    if len(domains) != 1:
        raise AnalysisInputError(f"the periodic runs' records have different analysis domains: {sorted(map(str, domains))}")
    (domain,) = domains
    if domain is None:
        return zones.x_end - zones.x_start
    return np.clip(np.minimum(zones.x_end, domain[1]) - np.maximum(zones.x_start, domain[0]), 0.0, None)


@dataclass(frozen=True)
class FullPasses:
    """A full run's complete passes of a stretch of its zones that ended in a window."""
    time_by_zone: np.ndarray  # (passes, zones of the run), s
    exit_time: np.ndarray     # when each pass left the stretch, s (ascending)
    snapshot: float           # the time of the snapshot of the particles still inside, s


def full_passes(run: Run, last_zone: int, after: float) -> FullPasses:
    """The passes of the zones up to `last_zone` (an index of the run's zones) that ended after `after`
    s and by the run's latest snapshot of the particles still inside ("inside" records).

    A particle that left through the outlet by the snapshot has passed the stretch; one still inside
    has, if it spent time downstream of the stretch. Between them they are every particle whose pass
    ended by the snapshot, so no pass of the window is missing however long the particles take
    downstream. A pass ends at entry + the time in the zones up to `last_zone`: exact for a particle
    that did not return upstream after it first left the stretch (for one that did, earlier by its
    time downstream before it returned). Outlet records after the snapshot (a run continued without a
    new one) are left out."""
    records = run.residence
    zones = run.zones
    inside = records.exit_reason == "inside"
    if not inside.any():
        raise AnalysisInputError(f"{run.path}: no 'inside' records: the passes of the section are known only with a "
                                 "snapshot of the particles still inside at the end (the full case's -v inside_records 1)")
    snapshot = float(records.exit_time[inside].max())
    latest = inside & np.isclose(records.exit_time, snapshot, rtol=0.0, atol=1e-9)
    left = (records.exit_reason == "outlet") & (records.exit_time <= snapshot)
    end = zones.x_end[last_zone]
    downstream = zones.x_start >= end - 1e-9
    upstream = zones.x_end <= end + 1e-9
    passed = left | (latest & (records.time_by_zone[:, downstream].sum(axis=1) > 0.0))
    exit_time = records.entry_time + records.time_by_zone[:, upstream].sum(axis=1)
    chosen = passed & (exit_time > after) & (exit_time <= snapshot)
    order = np.argsort(exit_time[chosen], kind="stable")
    return FullPasses(records.time_by_zone[chosen][order], exit_time[chosen][order], snapshot)


def balance_passage(run: Run, zone_indices: Sequence[int], weights: Sequence[float] | np.ndarray, length: float,
                    start: float) -> Estimate:
    """Mean time per passage (s) of the zones together by mass balance: length × Σ m / Σ m v_x over
    the blocks from `start` on, each zone's mass times its weight; nan when the net flux is not forward."""
    stats = run.elements
    used, _ = _steady_blocks(run, start)
    mass = stats.column("mass")[used][:, list(zone_indices)] * np.asarray(weights, dtype=float)
    momentum = mass * stats.column("mean_axial_velocity")[used][:, list(zone_indices)]
    return estimate_ratio(length * mass.sum(axis=1), momentum.sum(axis=1), detect=False)


def _passage_estimate(samples: np.ndarray) -> Estimate:
    if len(samples) < 2:
        return Estimate(math.nan, math.nan, len(samples), float(len(samples)), math.nan)
    return mean_residence(samples, np.arange(len(samples), dtype=float))


@dataclass(frozen=True)
class MachineResidence:
    records: Estimate   # mean residence time of the particles that left through the outlet in the window, s
    holdup: Estimate    # mass on every element, kg
    outflow: Estimate   # mass flow at the last sensor, kg/h

    def mass_balance(self) -> tuple[float, float]:
        """τ = M / ṁ (s) and its 95 % half-width (first order in the two relative half-widths)."""
        tau = self.holdup.mean / (self.outflow.mean / SECONDS_PER_HOUR)
        relative = math.hypot(self.holdup.half_width / self.holdup.mean, self.outflow.half_width / self.outflow.mean)
        return tau, tau * relative

    def text(self) -> str:
        tau, half_width = self.mass_balance()
        resolved = self.holdup.resolved and self.outflow.resolved
        balance = format_interval(tau, half_width) + " s" + ("" if resolved else " (indicative: too few independent samples)")
        return (f"Mean residence time of the full granulator: {self.records.text('s')} over the "
                f"{self.records.samples} particles that left through the outlet in the window; hold-up / throughput "
                f"{balance} (hold-up {self.holdup.mean * 1e3:.4g} g, outflow {self.outflow.text('kg/h')}).")


def machine_residence(full_run: Run, start: float) -> MachineResidence:
    """The full run's mean residence time from `start` s on: outlet records, and hold-up over throughput."""
    records = full_run.residence
    left = full_run.records(start) & (records.exit_reason == "outlet")
    if np.count_nonzero(left) < 2:
        raise AnalysisInputError(f"{full_run.path}: {np.count_nonzero(left)} particles left through the outlet after "
                                 f"{start:g} s; a mean residence time needs at least 2")
    used, times = _steady_blocks(full_run, start)
    holdup = estimate_mean(full_run.elements.column("mass")[used].sum(axis=1), times, float(times[0]))
    outflow = full_run.sensor_flows(start)[full_run.massflow.sensor_names[-1]]
    if not outflow.mean > 0:
        raise AnalysisInputError(f"{full_run.path}: the outlet sensor's mean flow after {start:g} s is {outflow.mean:.3g} kg/h; "
                                 "hold-up over throughput needs material leaving")
    return MachineResidence(mean_residence(records.residence_time[left], records.exit_time[left]), holdup, outflow)


@dataclass(frozen=True)
class DomainComparison:
    rows: list[DomainRow]
    rtds: list[RTDComparison]
    samples: dict[str, dict[str, np.ndarray]]  # run label -> scope -> times per passage
    holdup: Estimate                          # the full run's section hold-up, kg
    periodic_holdup: float                    # the periodic runs' mass, kg
    residence: MachineResidence               # the full granulator's mean residence time
    records_truncated: dict[str, str]         # run -> why it has no passes to count


def compare_domains(full_run: Run, periodic_runs: Sequence[Run], full_start: float,
                    periodic_start: float) -> DomainComparison:
    periodic_zones = periodic_runs[0].zones
    full_zones = full_run.zones
    index = section_indices(full_zones, periodic_zones)
    full = full_run.key_estimates(start=full_start, reference_zones=periodic_zones)
    each = [run.key_estimates(start=periodic_start) for run in periodic_runs]
    rows: list[DomainRow] = []
    for quantity in (SOLID_FRACTION, SPEED, AXIAL_VELOCITY):
        for label in periodic_zones.labels:
            key = (quantity, label)
            periodic = combine_replicas([e[key] for e in each])
            rows.append(DomainRow(quantity, label, full[key], periodic, difference(full[key], periodic)))
    section_flux = _section_flux(full_run, periodic_zones, full_start)
    periodic_flux = combine_replicas([e[(MASS_FLOW, DOMAIN_FLUX)] for e in each])
    rows.insert(0, DomainRow(MASS_FLOW, SECTION_FLUX, section_flux, periodic_flux,
                             difference(section_flux, periodic_flux)))
    kneading = [j for j, kind in enumerate(periodic_zones.kind) if kind == "kneading"]
    conveying = [j for j, kind in enumerate(periodic_zones.kind) if kind == "conveying"]
    scopes = {CONVEYING: conveying, KNEADING_BLOCK: kneading, SECTION: list(range(len(periodic_zones))),
              **{label: [j] for j, label in enumerate(periodic_zones.labels)}}
    periodic_length = periodic_zones.x_end - periodic_zones.x_start
    share = periodic_length / (full_zones.x_end - full_zones.x_start)[index]   # the full run's zones, scaled
    # the periodic records count time only inside the analysis domain (not in the buffers at its ends):
    # the full run's record times are scaled to the same part of each element
    counted = counted_lengths(periodic_zones, periodic_runs)
    record_share = counted / (full_zones.x_end - full_zones.x_start)[index]
    samples: dict[str, dict[str, np.ndarray]] = {"full": {}, "periodic": {}}
    residence = machine_residence(full_run, full_start)
    section_length = float(periodic_length.sum())
    full_after = full_start + RECORD_HORIZON * balance_passage(full_run, index, share, section_length, full_start).mean
    truncated: dict[str, str] = {}
    try:
        passes = full_passes(full_run, max(index), full_after)
        if len(passes.exit_time) < 2:
            truncated["full"] = (f"{len(passes.exit_time)} passes of the section ended between {full_after:.3g} s "
                                 f"({RECORD_HORIZON:g} balance times of the section after the steady start) and the "
                                 f"snapshot at {passes.snapshot:.3g} s")
    except AnalysisInputError as missing:
        passes, truncated["full"] = None, str(missing)
    periodic_horizons = [RECORD_HORIZON * balance_passage(d, scopes[SECTION], np.ones(len(periodic_zones)),
                                                          section_length, periodic_start).mean
                         for d in periodic_runs]
    for scope, zones in scopes.items():
        length = float(periodic_length[zones].sum())
        full_balance = balance_passage(full_run, [index[j] for j in zones], share[zones], length, full_start)
        periodic_balance = combine_replicas([balance_passage(d, zones, np.ones(len(zones)), length, periodic_start)
                                             for d in periodic_runs])
        rows.append(DomainRow(TIME_BY_BALANCE, scope, full_balance, periodic_balance,
                              difference(full_balance, periodic_balance)))
        samples["full"][scope] = (np.zeros(0) if passes is None or "full" in truncated
                                  else passes.time_by_zone[:, [index[j] for j in zones]] @ record_share[zones])
        by_run = [passage_times(d, zones, periodic_start, horizon=h) for d, h in zip(periodic_runs, periodic_horizons)]
        samples["periodic"][scope] = np.concatenate(by_run)
        if scope == SECTION:
            section_by_run = by_run
        if len(samples["full"][scope]) < 2 and all(len(t) < 2 for t in by_run):
            continue
        # one side may have no usable records (a row with "no data"): the other still checks its balance time
        full_time = _passage_estimate(samples["full"][scope])
        periodic_time = combine_replicas([_passage_estimate(t) for t in by_run if len(t) >= 2] or [_passage_estimate(by_run[0])])
        rows.append(DomainRow(TIME_PER_PASSAGE, scope, full_time, periodic_time, difference(full_time, periodic_time)))
    truncated.update({str(d.path): (f"its records end before {h:.3g} s after its first entry ({RECORD_HORIZON:g} balance "
                               "times of the section): only the fast passes would have completed")
                      for d, h, times in zip(periodic_runs, periodic_horizons, section_by_run) if len(times) < 2})
    rtds = [compare_rtds(samples["full"][scope], samples["periodic"][scope], scope)
            for scope in RTD_SCOPES
            if min(len(samples["full"][scope]), len(samples["periodic"][scope])) >= MIN_RECORDS]
    masses = [float(run.elements.column("mass")[-1].sum()) for run in periodic_runs]
    return DomainComparison(rows, rtds, {"full": {s: samples["full"][s] for s in RTD_SCOPES},
                                         "periodic": {s: samples["periodic"][s] for s in RTD_SCOPES}},
                            section_holdup(full_run, periodic_zones, full_start), float(np.mean(masses)),
                            residence, truncated)


UNITS = {MASS_FLOW: "kg/h", SOLID_FRACTION: "-", SPEED: "m/s", AXIAL_VELOCITY: "m/s", TIME_PER_PASSAGE: "s",
         TIME_BY_BALANCE: "s"}


def domains_markdown(comparison: DomainComparison) -> str:
    lines = [f"Hold-up on the section's elements in the full run: {comparison.holdup.mean * 1e3:.3g} g (in kg: "
             f"{comparison.holdup.text('kg')}); the periodic runs hold {comparison.periodic_holdup * 1e3:.3g} g.",
             "", comparison.residence.text(), "",
             "| quantity | scope | full | periodic | periodic − full | significant |", "|---|---|---|---|---|---|"]
    for r in comparison.rows:
        unit = UNITS[r.quantity]
        relative = f" ({r.difference.value / r.full.mean:+.0%})" if r.full.mean else ""
        lines.append(f"| {r.quantity} ({unit}) | {r.scope} | {r.full.text()} | {r.periodic.text()} | "
                     f"{r.difference.text(unit)}{relative} | {'yes' if r.difference.significant else 'no'} |")
    if comparison.records_truncated:
        lines += ["", "Time per passage from the records: no passes counted for"]
        lines += [f"- {run}: {why}" for run, why in comparison.records_truncated.items()]
    if comparison.rtds or any(r.quantity == TIME_PER_PASSAGE for r in comparison.rows):
        lines += ["", "Time per passage from the records: over the part of each element inside the periodic runs' "
                      "analysis domain (their records do not count the buffers at its ends; the full run's times are "
                      "scaled to the same lengths). By mass balance: over the whole elements."]
    if comparison.rtds:
        full_count, periodic_count = (len(comparison.samples[side][SECTION]) for side in ("full", "periodic"))
        lines += ["", f"Distributions of the time per passage ({full_count} passes of the full run, {periodic_count} "
                      f"of the periodic runs): KS distance D, agreement when D ≤ {AGREEMENT_KS_DISTANCE:g}; the KS test's "
                      "p-value takes the passes as independent.", "",
                  "| time per passage of | KS distance D | p-value | mean, periodic against full | agree |",
                  "|---|---|---|---|---|"]
        lines += [f"| {c.scope} | {c.ks_distance:.3f} | {c.ks_p_value:.2g} | {c.mean_difference:+.0%} | "
                  f"{'yes' if c.agree else 'no'} |" for c in comparison.rtds]
    return "\n".join(lines) + "\n"
