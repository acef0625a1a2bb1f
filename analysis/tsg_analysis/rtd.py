"""Residence-time distributions: E(t), F(t), moments, tanks-in-series and axial-dispersion fits,
and the agreement of two distributions.

Models (t̄ = mean residence time, s = σ²/t̄² the normalised variance):
- tanks in series: E(t) = Gamma(N, t̄/N) density. Moments: N = 1/s. Least squares: t̄ fixed at the
  sample mean, N chosen to minimise the squared error of the model density against the E(t)
  histogram (the mean is well determined by the sample; the shape is then fitted on the whole
  curve rather than on the variance, which the tail dominates).
- axial dispersion, closed–closed vessel (Danckwerts boundary conditions): t̄ = τ and
  s = 2/Pe − 2/Pe² (1 − e^(−Pe)); Pe from the moments (no closed-form E(t), so no curve fit).
- axial dispersion, open–open vessel: E_θ(θ) = sqrt(Pe/(4πθ)) exp(−Pe (1−θ)²/(4θ)) with θ = t/τ,
  t̄ = τ (1 + 2/Pe), σ²/τ² = 2/Pe + 8/Pe²; Pe from the moments and by least squares on E(t) with
  t̄ fixed at the sample mean, as above.
A plug flow (σ² = 0) has N = Pe = ∞.
Agreement of two distributions: the two-sample Kolmogorov–Smirnov distance D = max |F₁ − F₂|;
they are said to agree when D ≤ AGREEMENT_KS_DISTANCE. Beside it, the two-sample KS test's p-value
(scipy.stats.ks_2samp), which takes the times as independent draws: with thousands of passes it
resolves differences far below AGREEMENT_KS_DISTANCE, so it says whether a difference is
resolved, not whether it matters.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .run_files import AnalysisInputError
from .uncertainty import Estimate, estimate_mean

MIN_RECORDS = 20  # fewer residence times make a histogram and its fits meaningless
AGREEMENT_KS_DISTANCE = 0.1
MAX_BINS = 200
MIN_BINS = 10
_TANKS_GRID = np.geomspace(0.5, 5000.0, 4000)  # step ratio 1.0023: finer than the sampling error of N
_PECLET_GRID = np.geomspace(0.05, 5.0e4, 4000)


@dataclass(frozen=True)
class RTDStatistics:
    count: int
    mean: float  # s
    variance: float  # s^2
    normalised_variance: float  # σ²/t̄²
    tanks_moments: float  # N
    tanks_least_squares: float
    peclet_closed_moments: float  # nan when s >= 1 (broader than one stirred tank)
    peclet_open_moments: float  # nan when s >= 2
    peclet_open_least_squares: float


@dataclass(frozen=True)
class RTDHistogram:
    edges: np.ndarray  # s
    density: np.ndarray  # E(t), 1/s, integrates to 1 over the bins

    @property
    def centres(self) -> np.ndarray:
        return 0.5 * (self.edges[1:] + self.edges[:-1])


def check_sample(times: np.ndarray, what: str) -> np.ndarray:
    times = np.asarray(times, dtype=np.float64)
    if len(times) < MIN_RECORDS:
        raise AnalysisInputError(f"{what}: {len(times)} residence times, an RTD needs at least {MIN_RECORDS}")
    if not np.all(np.isfinite(times)) or np.any(times < 0):
        raise AnalysisInputError(f"{what}: residence times must be finite and non-negative")
    return times


def mean_residence(times: np.ndarray, exit_time: np.ndarray) -> Estimate:
    """Mean residence time ± 95 % interval. Records are taken in exit order: particles that leave
    close together travelled together, and the statistical inefficiency of that series accounts for it."""
    order = np.argsort(exit_time, kind="stable")
    return estimate_mean(np.asarray(times, dtype=np.float64)[order], detect=False)


def histogram_edges(times: np.ndarray) -> np.ndarray:
    """Bins from 0 to the longest time, width by the Freedman–Diaconis rule, MIN_BINS..MAX_BINS."""
    longest = float(times.max())
    if times.min() == longest:  # all times equal (plug flow): one narrow bin
        half_width = max(1e-3 * longest, 1e-12)
        return np.array([longest - half_width, longest + half_width])
    q25, q75 = np.percentile(times, [25, 75])
    width = 2.0 * (q75 - q25) * len(times) ** (-1.0 / 3.0)
    bins = int(np.clip(np.ceil(longest / width) if width > 0 else MAX_BINS, MIN_BINS, MAX_BINS))
    return np.linspace(0.0, longest * (1 + 1e-9), bins + 1)


def rtd_histogram(times: np.ndarray, edges: np.ndarray | None = None) -> RTDHistogram:
    edges = histogram_edges(times) if edges is None else edges
    density, _ = np.histogram(times, bins=edges, density=True)
    return RTDHistogram(edges, density)


def cumulative_distribution(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """F(t) of the sample: the sorted times and the fraction of times <= each."""
    ordered = np.sort(times)
    return ordered, np.arange(1, len(ordered) + 1) / len(ordered)


def tanks_in_series_density(t: np.ndarray, mean: float, tanks: np.ndarray | float) -> np.ndarray:
    """E(t) of N equal stirred tanks (Gamma(N, mean/N)); `tanks` may be an array (rows)."""
    tanks = np.atleast_1d(np.asarray(tanks, dtype=np.float64))[:, None]
    t = np.maximum(np.asarray(t, dtype=np.float64)[None, :], 1e-300)
    log_gamma = np.array([math.lgamma(n) for n in tanks[:, 0]])[:, None]
    scale = mean / tanks
    log_e = (tanks - 1) * np.log(t) - t / scale - log_gamma - tanks * np.log(scale)
    return np.squeeze(np.exp(log_e), axis=0) if tanks.shape[0] == 1 else np.exp(log_e)


def open_dispersion_density(t: np.ndarray, mean: float, peclet: np.ndarray | float) -> np.ndarray:
    """E(t) of the open–open axial dispersion model with mean residence time `mean`."""
    peclet = np.atleast_1d(np.asarray(peclet, dtype=np.float64))[:, None]
    tau = mean / (1 + 2 / peclet)
    theta = np.maximum(np.asarray(t, dtype=np.float64)[None, :], 1e-300) / tau
    e = np.sqrt(peclet / (4 * np.pi * theta)) * np.exp(-peclet * (1 - theta) ** 2 / (4 * theta)) / tau
    return np.squeeze(e, axis=0) if peclet.shape[0] == 1 else e


def closed_dispersion_variance(peclet: np.ndarray | float) -> np.ndarray:
    peclet = np.asarray(peclet, dtype=np.float64)
    return 2 / peclet - 2 / peclet**2 * (1 - np.exp(-peclet))


def closed_peclet_from_variance(normalised_variance: float) -> float:
    """Invert s(Pe) of the closed–closed model (monotone decreasing from 1 at Pe→0 to 0)."""
    if normalised_variance == 0:
        return math.inf
    if normalised_variance >= 1:
        return math.nan
    low, high = 1e-9, 1e9
    for _ in range(200):  # bisection on log Pe: s(Pe) has no closed inverse
        middle = math.sqrt(low * high)
        if closed_dispersion_variance(middle) > normalised_variance:
            low = middle
        else:
            high = middle
    return math.sqrt(low * high)


def open_peclet_from_variance(normalised_variance: float) -> float:
    """Solve s = (2u + 8u²)/(1 + 2u)² for u = 1/Pe (s = σ²/t̄², valid for s < 2)."""
    s = normalised_variance
    if s == 0:
        return math.inf
    if s >= 2:
        return math.nan
    inverse = (2 * s - 1 + math.sqrt(1 + 4 * s)) / (8 - 4 * s)
    return 1 / inverse


def _least_squares_on_grid(histogram: RTDHistogram, model_rows: np.ndarray, grid: np.ndarray) -> float:
    errors = np.sum((model_rows - histogram.density[None, :]) ** 2, axis=1)
    return float(grid[np.nanargmin(errors)])


def rtd_statistics(times: np.ndarray, what: str = "RTD") -> RTDStatistics:
    times = check_sample(times, what)
    mean = float(times.mean())
    variance = float(times.var(ddof=1))
    if mean <= 0:
        raise AnalysisInputError(f"{what}: mean residence time is zero")
    s = variance / mean**2
    if variance == 0:
        return RTDStatistics(len(times), mean, 0.0, 0.0, math.inf, math.inf, math.inf, math.inf, math.inf)
    histogram = rtd_histogram(times)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        tanks_fit = _least_squares_on_grid(
            histogram, tanks_in_series_density(histogram.centres, mean, _TANKS_GRID), _TANKS_GRID)
        peclet_fit = _least_squares_on_grid(
            histogram, open_dispersion_density(histogram.centres, mean, _PECLET_GRID), _PECLET_GRID)
    return RTDStatistics(
        count=len(times), mean=mean, variance=variance, normalised_variance=s,
        tanks_moments=1 / s, tanks_least_squares=tanks_fit,
        peclet_closed_moments=closed_peclet_from_variance(s),
        peclet_open_moments=open_peclet_from_variance(s),
        peclet_open_least_squares=peclet_fit,
    )


def ks_distance(first: np.ndarray, second: np.ndarray) -> float:
    """Two-sample Kolmogorov–Smirnov distance max_t |F₁(t) − F₂(t)|."""
    first, second = np.sort(first), np.sort(second)
    at = np.concatenate([first, second])
    f1 = np.searchsorted(first, at, side="right") / len(first)
    f2 = np.searchsorted(second, at, side="right") / len(second)
    return float(np.max(np.abs(f1 - f2)))


@dataclass(frozen=True)
class RTDComparison:
    scope: str
    ks_distance: float
    mean_difference: float  # (mean of run − mean of reference) / mean of reference
    agree: bool
    ks_p_value: float       # two-sample KS test, the times taken as independent


def compare_rtds(reference: np.ndarray, other: np.ndarray, scope: str) -> RTDComparison:
    from scipy.stats import ks_2samp

    distance = ks_distance(reference, other)
    difference = (float(np.mean(other)) - float(np.mean(reference))) / float(np.mean(reference))
    p_value = float(ks_2samp(reference, other).pvalue)
    return RTDComparison(scope, distance, difference, distance <= AGREEMENT_KS_DISTANCE, p_value)
