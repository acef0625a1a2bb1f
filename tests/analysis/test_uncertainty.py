"""Intervals on synthetic series with known answers: AR(1) of known statistical inefficiency
g = (1 + φ)/(1 − φ), white noise, a drifting series, start-up detection, replicas, differences."""
import math
import time

import numpy as np
import pytest
from scipy.signal import lfilter

from tsg_analysis.uncertainty import (MIN_INDEPENDENT, MIN_REPLICAS, Difference, Estimate, combine_replicas, difference,
                                      replica_outlier,
                                      estimate_mean, estimate_ratio, format_interval)

SERIES = 1000


def ar1(rng: np.random.Generator, count: int, length: int, phi: float, sigma: float = 1.0) -> np.ndarray:
    """`count` AR(1) series x_t = φ x_{t−1} + ε_t started in their stationary distribution (mean 0)."""
    noise = rng.normal(0.0, sigma, (count, length))
    first = rng.normal(0.0, sigma / math.sqrt(1 - phi**2), count)
    series, _ = lfilter([1.0], [1.0, -phi], noise, axis=1, zi=(phi * first)[:, None])
    return series


def coverage(series: np.ndarray, truth: float) -> tuple[float, list[Estimate]]:
    estimates = [estimate_mean(row, detect=False) for row in series]
    covered = [abs(e.mean - truth) <= e.half_width for e in estimates]
    return float(np.mean(covered)), estimates


@pytest.mark.parametrize("phi, length", [(0.8, 2000), (0.5, 1000)])
def test_ar1_coverage_and_inefficiency(phi, length):
    rng = np.random.default_rng(15)
    truth = 3.0
    fraction, estimates = coverage(truth + ar1(rng, SERIES, length, phi), truth)
    assert 0.93 <= fraction <= 0.97, f"coverage {fraction:.3f} of the nominal 95 % interval"
    g_known = (1 + phi) / (1 - phi)
    g_mean = np.mean([e.statistical_inefficiency for e in estimates])
    print(f"AR(1) φ={phi} n={length}: coverage {fraction:.3f}, mean g {g_mean:.2f} (known {g_known:.2f})")
    assert g_mean == pytest.approx(g_known, rel=0.08)
    assert all(e.resolved for e in estimates)


def test_white_noise():
    rng = np.random.default_rng(16)
    fraction, estimates = coverage(rng.normal(10.0, 2.0, (SERIES, 500)), 10.0)
    print(f"white noise n=500: coverage {fraction:.3f}, mean g "
          f"{np.mean([e.statistical_inefficiency for e in estimates]):.3f}, "
          f"drift false alarms {np.mean([bool(e.drift) for e in estimates]):.3f}")
    assert 0.93 <= fraction <= 0.97
    # pymbar sums at least 3 lags (mintime): on 500 white-noise samples g comes out about 1.1, not 1.0
    assert 1.0 <= np.mean([e.statistical_inefficiency for e in estimates]) <= 1.15
    # half-width of white noise: t(0.975, n−1) σ/√n = 1.965 · 2/√500 ≈ 0.176
    assert np.median([e.half_width for e in estimates]) == pytest.approx(1.965 * 2.0 / math.sqrt(500), rel=0.1)
    false_alarms = np.mean([bool(e.drift) for e in estimates])
    assert false_alarms < 0.03, f"{false_alarms:.1%} of stationary series flagged as drifting"


def test_drifting_series_is_flagged_not_stationary():
    # the main job: the flux falls from about 12 to 8 kg/h across the window, with 30 % noise
    rng = np.random.default_rng(17)
    ramp = np.linspace(12.0, 8.0, 1000)
    series = ramp + ar1(rng, 200, 1000, 0.5, sigma=3.0 * math.sqrt(1 - 0.25))
    flagged = [estimate_mean(row, detect=False).drift for row in series]
    print(f"drifting 12 → 8 kg/h: {np.mean(flagged):.3f} flagged")
    assert np.mean(flagged) > 0.95
    assert "drifting" in estimate_mean(series[0], detect=False).text() or not flagged[0]


def test_start_up_is_detected_and_reported_beside_the_chosen_one():
    rng = np.random.default_rng(18)
    times = np.arange(4000) * 1e-3  # s
    start_up = 20.0 * np.exp(-times / 0.1)  # decays below the noise after about 0.5 s
    series = 5.0 + start_up + ar1(rng, 1, len(times), 0.5)[0]
    estimate = estimate_mean(series, times, start=0.0)
    print(f"start-up detected at {estimate.detected_start} s")
    assert estimate.chosen_start == 0.0
    assert 0.25 <= estimate.detected_start <= 1.2
    from_detected = estimate_mean(series, times, start=estimate.detected_start)
    assert abs(from_detected.mean - 5.0) <= from_detected.half_width
    # the too-short chosen start-up looks like a long correlation: far fewer independent samples
    assert estimate.independent_samples < from_detected.independent_samples / 10


def test_too_few_independent_samples_gives_no_number():
    rng = np.random.default_rng(19)
    short = estimate_mean(14.0 + ar1(rng, 1, 6, 0.3)[0], detect=False)
    assert not short.resolved and short.independent_samples < MIN_INDEPENDENT
    text = short.text("kg/h")
    assert text.startswith("window too short: too few independent samples") and "indicative" in text
    assert estimate_mean(np.array([1.0]), detect=False).text().startswith("window too short")
    correlated = estimate_mean(ar1(rng, 1, 60, 0.95)[0], detect=False)  # 60 samples, ≈ 1.5 independent
    assert not correlated.resolved


def test_a_difference_within_its_interval_is_never_resolved():
    rng = np.random.default_rng(20)
    pairs = 1.0 + ar1(rng, 400, 300, 0.6)
    estimates = [estimate_mean(row, detect=False) for row in pairs]
    shifts = rng.uniform(-0.6, 0.6, 200)
    for shift, a, b in zip(shifts, estimates[::2], estimates[1::2]):
        b = Estimate(b.mean + shift, b.standard_error, b.samples, b.independent_samples, b.half_width)
        d = difference(a, b)
        assert d.value == pytest.approx(b.mean - a.mean)
        if abs(d.value) <= d.half_width:
            assert not d.significant and d.text().startswith("not resolved")
            assert f"{d.value:+.2f}" not in d.text()
        else:
            assert d.significant and d.text().endswith("(significant)")
    # an unresolved input never gives a resolved difference, however large
    short = estimate_mean(np.array([1.0, 2.0, 1.5]), detect=False)
    assert not difference(estimates[0], Estimate(100.0, *list(vars(short).values())[1:])).significant


def test_difference_interval_covers_the_true_difference():
    rng = np.random.default_rng(21)
    first = [estimate_mean(row, detect=False) for row in ar1(rng, SERIES, 600, 0.7)]
    second = [estimate_mean(row, detect=False) for row in 0.2 + ar1(rng, SERIES, 900, 0.4)]
    covered = [abs(difference(a, b).value - 0.2) <= difference(a, b).half_width for a, b in zip(first, second)]
    print(f"differences: coverage {np.mean(covered):.3f}")
    assert 0.93 <= np.mean(covered) <= 0.97


def test_replicas_combine_with_correct_coverage_and_widen_when_they_disagree():
    rng = np.random.default_rng(22)
    replicas = 7.0 + ar1(rng, 3 * SERIES, 800, 0.6)
    estimates = [estimate_mean(row, detect=False) for row in replicas]
    combined = [combine_replicas(estimates[i:i + 3]) for i in range(0, len(estimates), 3)]
    print(f"replica triples: coverage {np.mean([abs(c.mean - 7.0) <= c.half_width for c in combined]):.3f}")
    assert all(c.replicas == 3 for c in combined)
    assert 0.93 <= np.mean([abs(c.mean - 7.0) <= c.half_width for c in combined]) <= 0.97
    single_width = np.median([e.half_width for e in estimates])
    assert np.median([c.half_width for c in combined]) == pytest.approx(single_width / math.sqrt(3), rel=0.15)
    # replicas whose means differ by far more than their intervals: the interval grows to cover them
    apart = [Estimate(m, 0.01, 100, 100.0, 0.02) for m in (1.0, 2.0, 3.0)]
    assert combine_replicas(apart).half_width > 1.0


def short_windows(rng: np.random.Generator, count: int, truth: float) -> tuple[list[Estimate], float]:
    """Windows far too short for a time-series interval (40 samples, g = 39), each starting in a
    transient that decays over 8 samples, as a start-up left in the window does; and the expected
    window mean those windows estimate (the transient included)."""
    length, transient = 40, 2.0 * np.exp(-np.arange(40) / 8.0)
    series = truth + transient + ar1(rng, count, length, 0.95)
    return [estimate_mean(row, detect=False) for row in series], truth + float(transient.mean())


def test_replica_means_give_intervals_where_time_series_cannot():
    rng = np.random.default_rng(24)
    estimates, expected = short_windows(rng, 3 * SERIES, 5.0)
    # alone, a window is "too short" (a few in 3 000 pass the gate on an underestimated g)
    assert np.mean([e.resolved for e in estimates]) < 0.02
    combined = [combine_replicas(estimates[i:i + 3]) for i in range(0, len(estimates), 3)]
    assert all(c.method == "replica means" and c.resolved and c.replicas == 3 for c in combined)
    fraction = np.mean([abs(c.mean - expected) <= c.half_width for c in combined])
    print(f"replica means of triples of short windows: coverage {fraction:.3f}")
    # at least 95 %; above it because the floor of the windows' own noise widens the triples whose
    # means lie close by chance (measured 0.978; without the floor 0.947)
    assert 0.94 <= fraction <= 0.99
    assert "(3 replicas)" in combined[0].text()
    # two replicas are too few: no number is claimed
    assert MIN_REPLICAS == 3 and not combine_replicas(estimates[:2]).resolved


def test_replica_means_are_never_narrower_than_their_windows_noise():
    # the 1 mm reference's case: three short windows whose means lie within 0.001 of each other by
    # chance, each window's own error 0.08 (too few independent samples to be resolved alone)
    windows = [Estimate(m, 0.08, 40, 5.0, 0.25) for m in (3.235, 3.236, 3.237)]
    combined = combine_replicas(windows)
    assert combined.method == "replica means" and combined.resolved
    assert combined.standard_error == pytest.approx(0.08 / math.sqrt(3))
    assert combined.half_width == pytest.approx(4.302652729911275 * 0.08 / math.sqrt(3))
    # replicas that scatter more than their windows' noise keep the scatter
    scattered = [Estimate(m, 0.01, 40, 5.0, 0.03) for m in (3.0, 3.2, 3.4)]
    assert combine_replicas(scattered).standard_error == pytest.approx(0.2 / math.sqrt(3))


def test_difference_of_replica_means_covers_the_true_difference():
    rng = np.random.default_rng(25)
    first, expected_first = short_windows(rng, 3 * SERIES, 5.0)
    second, expected_second = short_windows(rng, 4 * SERIES, 5.3)
    differences = [difference(combine_replicas(first[3 * i:3 * i + 3]), combine_replicas(second[4 * i:4 * i + 4]))
                   for i in range(SERIES)]
    truth = expected_second - expected_first
    fraction = np.mean([abs(d.value - truth) <= d.half_width for d in differences])
    print(f"differences of replica means (3 against 4 replicas): coverage {fraction:.3f}")
    assert 0.93 <= fraction <= 0.98  # Welch's degrees of freedom are slightly conservative at 2-3 per side
    assert all(d.inputs_resolved for d in differences)


def test_mass_weighted_ratio_interval():
    rng = np.random.default_rng(23)
    n = 2000
    truth = 0.25
    masses = 1e-3 * (1.0 + 0.3 * ar1(rng, 300, n, 0.5).clip(-3, 3))
    velocities = truth + 0.1 * ar1(rng, 300, n, 0.7)
    covered = []
    for mass, velocity in zip(masses, velocities):
        estimate = estimate_ratio(mass * velocity, mass, detect=False)
        covered.append(abs(estimate.mean - truth) <= estimate.half_width)
    print(f"mass-weighted ratios: coverage {np.mean(covered):.3f}")
    assert 0.92 <= np.mean(covered) <= 0.98  # 300 series: ±2.5 % is three binomial standard deviations


def test_formatting():
    assert format_interval(13.8391, 0.4123) == "13.84 ± 0.41"
    assert format_interval(13.8391, 4.123) == "13.8 ± 4.1"
    assert format_interval(1383.91, 41.23) == "1384 ± 41"
    assert format_interval(-0.02, 0.0031, signed=True) == "-0.0200 ± 0.0031"
    assert Difference(1.0, 0.5, 0.1, True).text("kg/h") == "+1.00 ± 0.50 kg/h, +10.0% (significant)"


def test_cost_of_intervals_on_a_million_records_and_a_10k_series():
    rng = np.random.default_rng(24)
    records = rng.gamma(8.0, 0.05, 1_000_000)
    series = ar1(rng, 1, 10_000, 0.9)[0]
    start = time.perf_counter()
    on_records = estimate_mean(records, detect=False)
    on_series = estimate_mean(series, np.arange(10_000) * 1e-3, start=1.0)
    elapsed = time.perf_counter() - start
    print(f"cost: {elapsed:.2f} s for 1 M records and a 10 k series with start-up detection")
    assert on_records.resolved and on_series.resolved and on_series.detected_start is not None
    assert elapsed < 5.0, f"{elapsed:.2f} s (measured under whatever load the machine has)"


def test_drift_quantile_is_the_two_sided_99_percent_normal_quantile():
    from scipy import stats

    from tsg_analysis.uncertainty import DRIFT_QUANTILE

    assert DRIFT_QUANTILE == pytest.approx(stats.norm.ppf(0.995), rel=1e-12)


@pytest.mark.parametrize("phi, length, at_most", [(0.95, 60, 0.01), (0.8, 60, 0.04), (0.5, 40, 0.10)])
def test_short_correlated_records_rarely_claim_a_wrong_number(phi, length, at_most):
    """g is underestimated on short records, so an interval claimed there misses more often than 5 %;
    the MIN_INDEPENDENT gate keeps such wrong claims rare (docs/statistics.md, Limits)."""
    rng = np.random.default_rng(25)
    estimates = [estimate_mean(row, detect=False) for row in ar1(rng, SERIES, length, phi)]
    wrong = np.mean([e.resolved and abs(e.mean) > e.half_width for e in estimates])
    claimed = np.mean([e.resolved for e in estimates])
    print(f"AR(1) φ={phi} n={length} (true independent samples {length * (1 - phi) / (1 + phi):.1f}): "
          f"{claimed:.1%} claimed, {wrong:.1%} of all series a wrong claim")
    assert wrong <= at_most


def test_drift_false_alarms_on_stationary_correlated_series():
    rng = np.random.default_rng(26)
    estimates = [estimate_mean(row, detect=False) for row in ar1(rng, SERIES, 200, 0.8)]
    false_alarms = np.mean([bool(e.drift) for e in estimates])
    print(f"AR(1) φ=0.8 n=200: drift tested on {np.mean([e.drift is not None for e in estimates]):.1%}, "
          f"false alarms {false_alarms:.1%} (nominal 1 %)")
    assert false_alarms <= 0.04


@pytest.mark.parametrize("replicas", [3, 6])
def test_replica_prediction_interval_covers_a_new_run_95_percent(replicas):
    # a new draw from the replicas' population falls within the 95 % prediction limit in 95 % of
    # trials (exact for normal draws); a draw shifted by 6 sigma is an outlier nearly always
    rng = np.random.default_rng(7)
    trials = 4000
    inside = shifted = 0
    for _ in range(trials):
        draws = rng.normal(10.0, 2.0, replicas + 1)
        statistic, limit = replica_outlier(draws[:-1], draws[-1])
        inside += abs(statistic) <= limit
        statistic, limit = replica_outlier(draws[:-1], draws[-1] + 12.0)
        shifted += abs(statistic) > limit
    assert 0.94 <= inside / trials <= 0.96
    assert shifted / trials > (0.5 if replicas == 3 else 0.9)
    with pytest.raises(ValueError, match="at least 2"):
        replica_outlier([1.0], 1.0)


def test_start_detection_within_the_first_half_ignores_a_dip_at_the_end():
    """A start-up over the first 20 % of a record, then stationary noise ending in a short dip (a
    record too short to average the dip away): the origin, searched in the first half, is found at
    the end of the start-up; it is never in the second half."""
    from tsg_analysis.uncertainty import detect_start

    rng = np.random.default_rng(3)
    n = 200
    found = []
    for _ in range(20):
        values = 1.0 + 0.05 * rng.normal(size=n)
        values[:40] += np.linspace(1.0, 0.0, 40)    # start-up: 40 samples
        values[-6:] -= 0.3                           # a dip in the last 6 samples
        start = detect_start(values, np.arange(n) * 0.01, within=0.5)
        assert start is not None and start <= 0.5 * n * 0.01
        found.append(start)
    assert 0.3 <= float(np.median(found)) <= 0.6, found
    with pytest.raises(ValueError, match="within"):
        detect_start(np.ones(20), within=0.0)
