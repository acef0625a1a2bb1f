"""The squeeze ledger of a run (squeezes.txt, fix squeeze/ledger; docs/stability.md): how often
particles are pressed between the screws and the barrel beyond the ledger's overlap threshold, how
deep, how fast they leave, and where.

Rates and mean release speeds carry 95 % intervals from the time series of the window
(uncertainty.estimate_mean: events per time bin, release speed per event in end-time order), so
bursts and particles that return widen them; peak overlaps and release speeds are also given as
quantiles (numpy, of the events in the window).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .run_files import SQUEEZE_KINDS, AnalysisInputError, SqueezeRecords, Zones
from .uncertainty import Estimate, estimate_mean

QUANTILES = (0.5, 0.9, 0.99, 1.0)
RATE_BINS = 40  # time bins of the window for the event rate's interval


@dataclass(frozen=True)
class SqueezeLedger:
    start: float  # s, the window (events that end in (start, end])
    end: float
    events: int
    distinct_particles: int
    events_per_particle: float  # how often the same particle returns
    rate: Estimate  # events per simulated second
    release_speed: Estimate  # m/s, mean over events
    peak_wall_quantiles: dict[float, float]  # δ/R
    peak_pair_quantiles: dict[float, float]
    release_speed_quantiles: dict[float, float]  # m/s
    by_kind: dict[str, int]
    by_zone: dict[str, int]  # element label -> events whose deepest point lies in it

    def text(self) -> str:
        def quantiles(values: dict[float, float], unit: str = "") -> str:
            return ", ".join(f"{'max' if q == 1.0 else f'{100 * q:g} %'} {v:.3g}{unit}" for q, v in values.items())
        span = self.end - self.start
        lines = [f"squeezes over {self.start:.4g}-{self.end:.4g} s ({span:.3g} s): {self.events} events, "
                 f"{self.distinct_particles} particles ({self.events_per_particle:.2f} events each)",
                 f"  rate               {self.rate.text('1/s')}",
                 f"  release speed      {self.release_speed.text('m/s')}; {quantiles(self.release_speed_quantiles, ' m/s')}",
                 f"  peak wall δ/R      {quantiles(self.peak_wall_quantiles)}",
                 f"  peak pair δ/R      {quantiles(self.peak_pair_quantiles)}",
                 "  kind               " + ", ".join(f"{k} {n}" for k, n in self.by_kind.items()),
                 "  where (element)    " + ", ".join(f"{k} {n}" for k, n in self.by_zone.items() if n)]
        return "\n".join(lines)


def _quantiles(values: np.ndarray) -> dict[float, float]:
    return {q: float(np.quantile(values, q)) for q in QUANTILES} if values.size else {q: float("nan") for q in QUANTILES}


def squeeze_ledger(records: SqueezeRecords, zones: Zones, start: float | None = None,
                   end: float | None = None) -> SqueezeLedger:
    """The ledger of the events that end in (start, end]; start/end default to the record's span
    (from its first event's start to its last event's end)."""
    if len(records) == 0:
        raise AnalysisInputError("squeezes.txt: no squeeze events (nothing to summarise)")
    ends = records["end_time"]
    lo = float(records["start_time"].min()) if start is None else start
    hi = float(ends.max()) if end is None else end
    if not hi > lo:
        raise AnalysisInputError(f"squeezes.txt: the window ({lo:g}, {hi:g}] s is empty")
    inside = (ends > lo) & (ends <= hi)
    if not inside.any():
        raise AnalysisInputError(f"squeezes.txt: no event ends in ({lo:g}, {hi:g}] s")
    chosen = {name: values[inside] for name, values in records.columns.items()}
    edges = np.linspace(lo, hi, RATE_BINS + 1)
    counts, _ = np.histogram(chosen["end_time"], bins=edges)
    rate = estimate_mean(counts / np.diff(edges), detect=False)
    order = np.argsort(chosen["end_time"], kind="stable")
    release = estimate_mean(chosen["release_speed"][order], detect=False)
    ids = chosen["id"].astype(np.int64)
    distinct = int(np.unique(ids).size)
    kinds = chosen["kind"].astype(np.int64)
    x = chosen["x"]
    zone_of = np.searchsorted(zones.x_end, x, side="right")
    by_zone = {label: int(np.count_nonzero(zone_of == k)) for k, label in enumerate(zones.labels)}
    return SqueezeLedger(
        start=lo, end=hi, events=int(inside.sum()), distinct_particles=distinct,
        events_per_particle=float(inside.sum()) / distinct, rate=rate, release_speed=release,
        peak_wall_quantiles=_quantiles(chosen["peak_wall_ratio"]),
        peak_pair_quantiles=_quantiles(chosen["peak_pair_ratio"]),
        release_speed_quantiles=_quantiles(chosen["release_speed"]),
        by_kind={name: int(np.count_nonzero(kinds == k)) for k, name in enumerate(SQUEEZE_KINDS)},
        by_zone=by_zone)
