"""Mean ± 95 % confidence interval of a correlated time series, replicas, differences of runs.

Method (docs/statistics.md): n samples of a stationary series with statistical inefficiency g carry
n/g independent samples, so the standard error of their mean is σ √(g/n) (Chodera et al. 2007,
J. Chem. Theory Comput. 3, 26; Flyvbjerg & Petersen 1989). g comes from
`pymbar.timeseries.statistical_inefficiency` (integrated normalised autocorrelation, summed to its
first zero crossing); the interval is Student's t with n/g − 1 degrees of freedom. The start of
stationarity is detected with `pymbar.timeseries.detect_equilibration` (the origin that maximises
the number of independent samples after it) and reported beside the start the analysis chose.
Non-linear statistics (mass-weighted averages, hold-up/throughput) use the same machinery on their
linearised pseudo-values (delta method): for R = Σa/Σb the series R + (a_t − R b_t)/b̄ has mean R
and carries R's fluctuation to first order.

Replicas (runs that differ only in the fill seed): when every replica's own interval is resolved,
they are combined by inverse-variance weights (Birge-scaled). Otherwise, from MIN_REPLICAS
replicas on, each replica's window mean is one independent sample of "the window mean of a run",
and the interval is Student's t over those means with R − 1 degrees of freedom: it needs no
autocorrelation estimate, so it holds for windows too short for a time-series interval, start-up
transients included (it then describes the window mean, not a steady state; drift stays flagged).

Drift: the window's two halves are compared, each with its own g; a difference beyond the 99 %
two-sided normal quantile flags the series as not stationary. Fewer than MIN_INDEPENDENT independent
samples: no number is claimed ("too few independent samples"), only an indicative interval.
"""
from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from types import ModuleType

import numpy as np

CONFIDENCE = 0.95
MIN_INDEPENDENT = 20.0  # fewer independent samples: g and so the interval are too uncertain to claim a number
DRIFT_QUANTILE = 2.5758293035489004  # Φ⁻¹(0.995): halves differ beyond it: drift (1 % false alarms)
MIN_REPLICAS = 3  # replica window means: R − 1 >= 2 degrees of freedom for their spread
MIN_INDEPENDENT_PER_HALF = 10.0  # the drift test needs this many independent samples in each half
DETECTION_ORIGINS = 200  # at most this many candidate origins for detect_equilibration (cost)


@dataclass(frozen=True)
class Estimate:
    """A mean with its 95 % interval and what the interval rests on."""

    mean: float
    standard_error: float  # nan: not computable (fewer than 2 samples)
    samples: int
    independent_samples: float  # samples / statistical inefficiency (summed over replicas)
    half_width: float  # of the 95 % interval; nan when not computable
    drift: bool | None = None  # halves differ beyond their intervals; None: too short to test
    detected_start: float | None = None  # where the record becomes stationary (pymbar), in the record's time unit
    chosen_start: float | None = None  # where the analysed window starts
    replicas: int = 1
    method: str = "time series"  # or "replica means": t over the replicas' window means

    @property
    def resolved(self) -> bool:
        """Enough independent samples for the interval to mean what it says."""
        if self.method == "replica means":
            return self.replicas >= MIN_REPLICAS and math.isfinite(self.half_width)
        return self.independent_samples >= MIN_INDEPENDENT and math.isfinite(self.half_width)

    @property
    def statistical_inefficiency(self) -> float:
        return self.samples / self.independent_samples if self.independent_samples > 0 else math.inf

    def text(self, unit: str = "") -> str:
        """'13.84 ± 0.41 kg/h', or why there is no number (with the indicative interval)."""
        unit = f" {unit}" if unit else ""
        if not math.isfinite(self.mean):
            return "no data"
        if not self.resolved and self.method == "replica means":
            indicative = f"; indicative {format_interval(self.mean, self.half_width)}{unit}" \
                if math.isfinite(self.half_width) else ""
            return f"too few replicas: {self.replicas} < {MIN_REPLICAS} of windows too short for a time-series " \
                   f"interval{indicative}"
        if not self.resolved:
            indicative = f"; indicative {format_interval(self.mean, self.half_width)}{unit}" \
                if math.isfinite(self.half_width) else ""
            return f"window too short: too few independent samples ({self.independent_samples:.1f} < " \
                   f"{MIN_INDEPENDENT:g}{indicative})"
        flag = " (drifting)" if self.drift else ""
        over = f" ({self.replicas} replicas)" if self.method == "replica means" else ""
        return f"{format_interval(self.mean, self.half_width)}{unit}{over}{flag}"

    def as_dict(self) -> dict:
        values = asdict(self)
        values.update(resolved=self.resolved, text=self.text())
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in values.items()}


@dataclass(frozen=True)
class Difference:
    """other − reference with its 95 % interval."""

    value: float
    half_width: float
    relative: float  # value / reference mean
    inputs_resolved: bool  # both estimates rest on enough independent samples

    @property
    def significant(self) -> bool:
        """Resolved: the interval excludes zero. A difference within its interval never is."""
        return self.inputs_resolved and math.isfinite(self.half_width) and abs(self.value) > self.half_width

    def text(self, unit: str = "") -> str:
        unit = f" {unit}" if unit else ""
        if not self.inputs_resolved:
            return "window too short: too few independent samples (or replicas)"
        if not self.significant:
            return f"not resolved (within ± {_round_significant(self.half_width)}{unit})"
        relative = f", {self.relative:+.1%}" if math.isfinite(self.relative) else ""
        return f"{format_interval(self.value, self.half_width, signed=True)}{unit}{relative} (significant)"

    def as_dict(self) -> dict:
        values = asdict(self)
        values.update(significant=self.significant, text=self.text())
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in values.items()}


def _round_significant(value: float, digits: int = 2) -> str:
    if value == 0 or not math.isfinite(value):
        return f"{value:g}"
    return f"{value:.{digits}g}"


def format_interval(mean: float, half_width: float, signed: bool = False) -> str:
    """Half-width to 2 significant digits and the mean to the same decimal place."""
    sign = "+" if signed else ""
    if not math.isfinite(half_width) or half_width <= 1e-12 * abs(mean):  # exact up to rounding
        return f"{mean:{sign}.6g} ± {0.0 if math.isfinite(half_width) else half_width:g}"
    decimals = max(0, 1 - int(math.floor(math.log10(abs(half_width)))))
    if decimals == 0:
        return f"{mean:{sign}.0f} ± {half_width:.0f}"
    return f"{mean:{sign}.{decimals}f} ± {half_width:.{decimals}f}"


def _timeseries() -> ModuleType:
    """pymbar.timeseries, imported on first use (pymbar and scipy take a second to import, which a
    command line that only checks its arguments should not pay)."""
    logging.getLogger("pymbar").setLevel(logging.ERROR)  # pymbar warns about JAX and its own caveats on import
    from pymbar import timeseries

    return timeseries


def t_quantile(degrees_of_freedom: float) -> float:
    from scipy import stats

    return float(stats.t.ppf(0.5 + CONFIDENCE / 2, max(degrees_of_freedom, 1.0)))


def statistical_inefficiency(values: np.ndarray) -> float:
    """g ≥ 1 of a series (1 for a constant one: its mean is exact)."""
    values = np.asarray(values, dtype=np.float64)
    if len(values) < 2 or np.ptp(values) == 0:
        return 1.0
    return float(_timeseries().statistical_inefficiency(values))


def _mean_and_error(values: np.ndarray) -> tuple[float, float, float]:
    """mean, standard error, independent samples."""
    n = len(values)
    if n == 0:
        return math.nan, math.nan, 0.0
    mean = float(values.mean())
    if n < 2:
        return mean, math.nan, float(n)
    g = statistical_inefficiency(values)
    return mean, float(values.std(ddof=1) * math.sqrt(g / n)), n / g


def _drift(values: np.ndarray) -> bool | None:
    half = len(values) // 2
    (m1, s1, n1), (m2, s2, n2) = _mean_and_error(values[:half]), _mean_and_error(values[half:])
    if min(n1, n2) < MIN_INDEPENDENT_PER_HALF or not (math.isfinite(s1) and math.isfinite(s2)):
        return None
    spread = math.hypot(s1, s2)
    if spread == 0:
        return bool(m1 != m2)
    return bool(abs(m2 - m1) > DRIFT_QUANTILE * spread)


def detect_start(values: np.ndarray, times: np.ndarray | None = None, within: float = 1.0) -> float | None:
    """Time (or index) from which the record is stationary: the origin that leaves the most
    independent samples after it, (N − t₀)/g(t₀) (Chodera 2016; pymbar's detect_equilibration), trying
    at most DETECTION_ORIGINS origins, all in the first `within` of the record (1: anywhere; 0.5: at
    least half the record stays, so that a dip near the end of a short noisy record cannot leave a
    window of a few samples). None when the record is too short (under 10 samples) to tell."""
    if not 0.0 < within <= 1.0:
        raise ValueError(f"within {within}: a fraction of the record, 0 < within <= 1")
    values = np.asarray(values, dtype=np.float64)
    if len(values) < 10 or not np.all(np.isfinite(values)):
        return None
    step = max(1, len(values) // DETECTION_ORIGINS)
    if np.ptp(values) == 0:
        origin = 0
    elif within == 1.0:
        origin = int(_timeseries().detect_equilibration(values, fast=True, nskip=step)[0])
    else:
        candidates = range(0, max(1, int(within * len(values))), step)
        independent = [(len(values) - t0) / statistical_inefficiency(values[t0:]) for t0 in candidates]
        origin = candidates[int(np.argmax(independent))]
    return float(times[origin]) if times is not None else float(origin)


def estimate_mean(values: np.ndarray, times: np.ndarray | None = None, start: float | None = None,
                  detect: bool = True) -> Estimate:
    """Mean ± 95 % interval of the samples at times ≥ `start` (all when None); start-up detection
    runs on the whole record and is reported beside `start`."""
    values = np.asarray(values, dtype=np.float64)
    if times is not None and len(times) != len(values):
        raise ValueError(f"{len(values)} values but {len(times)} times")
    window = values if times is None or start is None else values[np.asarray(times) >= start]
    window = window[np.isfinite(window)]
    mean, error, independent = _mean_and_error(window)
    half_width = t_quantile(independent - 1) * error if independent >= 2 else math.nan
    return Estimate(mean, error, len(window), independent, half_width, _drift(window),
                    detect_start(values, times) if detect else None, start)


def ratio_pseudo_values(numerator: np.ndarray, denominator: np.ndarray) -> tuple[float, np.ndarray]:
    """R = Σa/Σb and the pseudo-values R + (a_t − R b_t)/b̄ (their mean is R; delta method)."""
    numerator, denominator = np.asarray(numerator, np.float64), np.asarray(denominator, np.float64)
    mean_denominator = float(denominator.mean()) if len(denominator) else math.nan
    if not mean_denominator > 0:
        return math.nan, np.full(len(numerator), math.nan)
    ratio = float(numerator.sum() / denominator.sum())
    return ratio, ratio + (numerator - ratio * denominator) / mean_denominator


def estimate_ratio(numerator: np.ndarray, denominator: np.ndarray, times: np.ndarray | None = None,
                   start: float | None = None, detect: bool = True) -> Estimate:
    """Σa/Σb over the window (e.g. a mass-weighted average: a = m v, b = m) ± 95 % interval."""
    numerator, denominator = np.asarray(numerator, np.float64), np.asarray(denominator, np.float64)
    inside = np.ones(len(numerator), bool) if times is None or start is None else np.asarray(times) >= start
    _, pseudo = ratio_pseudo_values(numerator[inside], denominator[inside])
    with np.errstate(invalid="ignore", divide="ignore"):
        per_sample = numerator / denominator  # the record for start-up detection
    estimate = estimate_mean(pseudo, detect=False)
    detected = detect_start(per_sample, times) if detect and np.all(denominator > 0) else None
    return Estimate(estimate.mean, estimate.standard_error, estimate.samples, estimate.independent_samples,
                    estimate.half_width, estimate.drift, detected, start)


def combine_replicas(estimates: Sequence[Estimate]) -> Estimate:
    """Runs that differ only in their seed. Every replica resolved: inverse-variance weighted mean;
    when the replicas scatter more than their intervals allow (Birge ratio √(χ²/(R−1)) > 1), the
    error is scaled up by it. Otherwise Student's t over the replicas' window means (replica_means),
    a number from MIN_REPLICAS replicas on."""
    if not estimates:
        raise ValueError("no replicas to combine")
    if len(estimates) == 1:
        return estimates[0]
    if not all(e.resolved for e in estimates):
        return replica_means(estimates)  # resolved from MIN_REPLICAS replicas on
    means = np.array([e.mean for e in estimates])
    errors = np.array([e.standard_error for e in estimates])
    independent = float(sum(e.independent_samples for e in estimates))
    samples = sum(e.samples for e in estimates)
    if not np.all(np.isfinite(errors)) or np.any(errors == 0):
        mean, error = float(means.mean()), (float(means.std(ddof=1) / math.sqrt(len(means)))
                                            if np.all(np.isfinite(means)) else math.nan)
    else:
        weights = 1.0 / errors**2
        mean = float(weights @ means / weights.sum())
        error = float(1.0 / math.sqrt(weights.sum()))
        birge_squared = float(weights @ (means - mean) ** 2) / (len(means) - 1)
        error *= math.sqrt(max(1.0, birge_squared))
    half_width = t_quantile(independent - len(estimates)) * error if math.isfinite(error) else math.nan
    return Estimate(mean, error, samples, independent, half_width, *_flags(estimates),
                    sum(e.replicas for e in estimates))


def _flags(estimates: Sequence[Estimate]) -> tuple[bool | None, float | None, float | None]:
    """(any drift, latest detected start, the chosen start) of replicas."""
    drifts = [e.drift for e in estimates if e.drift is not None]
    starts = [e.detected_start for e in estimates if e.detected_start is not None]
    return (any(drifts) if drifts else None), (max(starts) if starts else None), estimates[0].chosen_start


def replica_means(estimates: Sequence[Estimate]) -> Estimate:
    """Each replica's window mean is one independent sample: mean ± t_{R−1} s/√R. Valid whatever
    the window's autocorrelation, because the replicas are independent runs. The error is never
    taken below what the windows' own fluctuation gives, √(Σ σᵢ²)/R (σᵢ: each window's time-series
    standard error, where every replica has one): with 3 replicas the scatter s rests on 2 degrees of
    freedom, and window means that happen to lie close would give an interval narrower than one
    window's noise allows (docs/statistics.md, "Replicas")."""
    means = np.array([e.mean for e in estimates], dtype=np.float64)
    if means.size < 2 or not np.all(np.isfinite(means)):
        error = math.nan
    else:
        error = float(means.std(ddof=1)) / math.sqrt(means.size)
        own = np.array([e.standard_error for e in estimates], dtype=np.float64)
        if np.all(np.isfinite(own)):
            error = max(error, float(np.sqrt(np.sum(own**2))) / means.size)
    half_width = t_quantile(means.size - 1) * error if math.isfinite(error) else math.nan
    # samples: all the replicas' samples; independent samples: one per replica (the window means)
    return Estimate(float(means.mean()), error, sum(e.samples for e in estimates), float(means.size), half_width,
                    *_flags(estimates), int(means.size), "replica means")


def replica_outlier(replicas: Sequence[float], value: float) -> tuple[float, float]:
    """Whether one more run (`value`) belongs to the population the replicas sample: the t statistic
    of `value` against the replicas' mean with the prediction error s √(1 + 1/n) (n replicas,
    sample standard deviation s), and its two-sided 95 % limit t_{n−1}. Needs no interval of its
    own: the replicas' scatter is the whole statistical error of one run's window mean (start-up
    included), so it also holds for windows too short for a time-series interval."""
    means = np.asarray(replicas, dtype=np.float64)
    if means.size < 2:
        raise ValueError(f"{means.size} replica(s): a prediction interval needs at least 2")
    spread = float(means.std(ddof=1)) * math.sqrt(1 + 1 / means.size)
    statistic = (value - float(means.mean())) / spread if spread > 0 else (0.0 if value == means.mean() else math.inf)
    return statistic, t_quantile(means.size - 1)


def difference(reference: Estimate, other: Estimate) -> Difference:
    """other − reference, interval with Welch–Satterthwaite degrees of freedom from the
    independent sample counts."""
    value = other.mean - reference.mean
    s1, s2 = reference.standard_error, other.standard_error
    error = math.hypot(s1, s2)
    if error > 0 and math.isfinite(error):
        dof = error**4 / (s1**4 / max(reference.independent_samples - 1, 1)
                          + s2**4 / max(other.independent_samples - 1, 1))
    else:
        dof = reference.independent_samples + other.independent_samples - 2
    relative = value / reference.mean if reference.mean != 0 else math.nan
    return Difference(value, t_quantile(dof) * error, relative, reference.resolved and other.resolved)
