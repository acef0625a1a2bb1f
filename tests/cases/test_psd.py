"""The discretised particle-size distribution of cases/psd.py against the truncated normal."""
import math
import os
from pathlib import Path

import numpy as np
import pytest

from tsg_cases import psd

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def truncated_normal_moment(k: int, sigma: float, lo: float = 0.5, hi: float = 1.5, n: int = 200001) -> float:
    """E[d^k] of normal(1, sigma) truncated to [lo, hi], by dense quadrature (independent of psd.py)."""
    d = np.linspace(lo, hi, n)
    weight = np.exp(-0.5 * ((d - 1) / sigma) ** 2)
    return float(np.trapezoid(d**k * weight, d) / np.trapezoid(weight, d))


@pytest.mark.parametrize("sigma", [0.05, 0.2])
def test_classes_conserve_number_and_mass_moments(sigma):
    diameters, fractions = psd.size_classes(sigma, 7)
    assert fractions.sum() == pytest.approx(1, abs=1e-12)
    # each class diameter carries its class's mean d^3: the mass per particle is exact
    assert np.dot(fractions, diameters**3) == pytest.approx(truncated_normal_moment(3, sigma), rel=2e-4)
    # the mean diameter is close (7 classes; exact only in the limit)
    assert np.dot(fractions, diameters) == pytest.approx(truncated_normal_moment(1, sigma), rel=2e-3)
    assert diameters.min() >= 0.5 and diameters.max() <= 1.5


@pytest.mark.parametrize("sigma", ["0.05", "0.2"])
def test_shipped_include_files_match_the_generator(sigma):
    shipped = (ROOT / "cases" / "include" / f"psd_s{sigma}.in").read_text()
    assert shipped == psd.include_text(float(sigma), 7), "regenerate: tsg-psd write ..."


def test_bad_arguments_are_rejected():
    with pytest.raises(ValueError, match="relative_sigma = -0.1"):
        psd.size_classes(-0.1, 7)
    with pytest.raises(ValueError, match="classes = 0"):
        psd.size_classes(0.05, 0)
