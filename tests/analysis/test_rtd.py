"""RTD moments and fits against exact answers: plug flow, tanks in series (Gamma samples), dispersion."""
import math

import numpy as np
import pytest

from tsg_analysis.rtd import (AGREEMENT_KS_DISTANCE, closed_dispersion_variance, closed_peclet_from_variance,
                              compare_rtds, cumulative_distribution, ks_distance, open_dispersion_density,
                              open_peclet_from_variance, rtd_histogram, rtd_statistics, tanks_in_series_density)
from tsg_analysis.run_files import AnalysisInputError

SAMPLES = 20_000
MEAN = 2.0


def gamma_sample(tanks, seed=7):
    return np.random.default_rng(seed).gamma(tanks, MEAN / tanks, SAMPLES)


def test_plug_flow_has_zero_variance_and_infinite_tanks():
    stats = rtd_statistics(np.full(500, 3.0))
    assert stats.mean == 3.0 and stats.variance == 0.0 and stats.normalised_variance == 0.0
    assert math.isinf(stats.tanks_moments) and math.isinf(stats.peclet_closed_moments)
    histogram = rtd_histogram(np.full(500, 3.0))
    assert np.sum(histogram.density * np.diff(histogram.edges)) == pytest.approx(1.0)


@pytest.mark.parametrize("tanks", [1.0, 5.0, 20.0])
def test_tanks_in_series_sample_gives_its_moments_and_n(tanks):
    stats = rtd_statistics(gamma_sample(tanks))
    variance = MEAN**2 / tanks
    # sampling error of the mean: σ/√n; of the variance: σ²·√((2 + 6/N)/n) (Gamma excess kurtosis 6/N)
    assert abs(stats.mean - MEAN) < 5 * math.sqrt(variance / SAMPLES)
    relative_variance_error = math.sqrt((2 + 6 / tanks) / SAMPLES)
    assert stats.variance == pytest.approx(variance, rel=5 * relative_variance_error)
    assert stats.normalised_variance == pytest.approx(1 / tanks, rel=6 * relative_variance_error)
    assert stats.tanks_moments == pytest.approx(tanks, rel=6 * relative_variance_error)
    assert stats.tanks_least_squares == pytest.approx(tanks, rel=0.08)


def test_dispersion_pe_inversions_are_exact():
    for peclet in (0.5, 3.0, 40.0, 400.0):
        assert closed_peclet_from_variance(float(closed_dispersion_variance(peclet))) == pytest.approx(peclet, rel=1e-9)
        s = (2 / peclet + 8 / peclet**2) / (1 + 2 / peclet) ** 2  # open–open σ²/t̄²
        assert open_peclet_from_variance(s) == pytest.approx(peclet, rel=1e-12)
    assert math.isnan(closed_peclet_from_variance(1.2))  # broader than one stirred tank


@pytest.mark.parametrize("peclet", [2.0, 20.0])
def test_open_dispersion_density_has_the_model_moments(peclet):
    t = np.linspace(1e-6, 40.0, 400_001)
    e = open_dispersion_density(t, MEAN, peclet)
    tau = MEAN / (1 + 2 / peclet)
    assert np.trapezoid(e, t) == pytest.approx(1.0, rel=1e-4)
    assert np.trapezoid(t * e, t) == pytest.approx(MEAN, rel=1e-4)
    variance = np.trapezoid((t - MEAN) ** 2 * e, t)
    assert variance == pytest.approx(tau**2 * (2 / peclet + 8 / peclet**2), rel=1e-3)


def test_open_dispersion_least_squares_recovers_pe_of_a_model_sample():
    # inverse-transform sample of the open–open density at Pe = 20
    t = np.linspace(1e-6, 10.0, 200_001)
    cdf = np.cumsum(open_dispersion_density(t, MEAN, 20.0))
    cdf /= cdf[-1]
    sample = np.interp(np.random.default_rng(3).uniform(size=SAMPLES), cdf, t)
    stats = rtd_statistics(sample)
    assert stats.peclet_open_least_squares == pytest.approx(20.0, rel=0.1)
    assert stats.peclet_open_moments == pytest.approx(20.0, rel=0.1)


def test_tanks_density_is_normalised_with_the_right_mean():
    t = np.linspace(1e-9, 30.0, 300_001)
    e = tanks_in_series_density(t, MEAN, 4.0)
    assert np.trapezoid(e, t) == pytest.approx(1.0, rel=1e-6)
    assert np.trapezoid(t * e, t) == pytest.approx(MEAN, rel=1e-6)


def test_cumulative_distribution_steps_to_one():
    ordered, fraction = cumulative_distribution(np.array([3.0, 1.0, 2.0, 2.0]))
    assert list(ordered) == [1.0, 2.0, 2.0, 3.0]
    assert list(fraction) == [0.25, 0.5, 0.75, 1.0]


def test_agreement_metric():
    same = compare_rtds(gamma_sample(6.0, seed=1), gamma_sample(6.0, seed=2), "total")
    assert same.ks_distance < 0.03 and same.agree
    shifted = compare_rtds(gamma_sample(6.0, seed=1), 1.3 * gamma_sample(6.0, seed=2), "total")
    assert shifted.ks_distance > AGREEMENT_KS_DISTANCE and not shifted.agree
    assert shifted.mean_difference == pytest.approx(0.3, abs=0.02)
    assert ks_distance(np.array([1.0, 2.0]), np.array([3.0, 4.0])) == 1.0


def test_too_few_records_is_an_input_error():
    with pytest.raises(AnalysisInputError, match="at least"):
        rtd_statistics(np.ones(3), "tiny")


def test_ks_p_value_rejects_at_its_level_for_one_distribution_and_resolves_a_shift():
    from tsg_analysis.rtd import compare_rtds
    rng = np.random.default_rng(5)
    same = [compare_rtds(rng.gamma(3.0, 1.0, 200), rng.gamma(3.0, 1.0, 300), "same").ks_p_value for _ in range(400)]
    assert 0.02 <= np.mean(np.array(same) < 0.05) <= 0.08   # p uniform when both are one distribution
    shifted = compare_rtds(rng.gamma(3.0, 1.0, 2000), 1.1 * rng.gamma(3.0, 1.0, 2000), "shifted")
    assert shifted.ks_p_value < 1e-3 and shifted.agree   # resolved, and yet within the agreement distance
