"""Same physics statistically (issue 8): the periodic demo granulator with the screws turned by the
stock path and by fix wall/gran/corotating, three static fills (seeds) each, gives per-element
solid fraction and mass-weighted axial velocity that agree within the run-to-run scatter.

Criterion: for every element and quantity, |mean_corotating − mean_stock| ≤ t · s_pooled · √(2/n)
with n = 3 runs per drive, s_pooled the seed-to-seed standard deviation pooled over both drives,
and t = 8.6, Student's t for 4 degrees of freedom at a two-sided 0.06 % level (1 % over the
16 comparisons, Bonferroni). The same criterion must reject the screws turning at 450 rpm instead
of 600 (a power check: the test can fail).
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tsg_analysis.run import Run

ROOT = Path(__file__).resolve().parents[2]
SEEDS = (1009, 2003, 3001)
T_CRITICAL = 8.6
# 0.01 s start-up + 0.02 s sampling at demo scale: 12 000 steps; 20 um meshes, on which the stock
# path costs 4 ms/step instead of 15 at the demo's 4 um
RUN = (("t_startup", 0.01), ("t_sample", 0.02), ("stats_every", 400), ("thermo_every", 4000))


def run_case(out: Path, drive: str, seed: int, rpm: float = 600) -> tuple[np.ndarray, np.ndarray]:
    command = [sys.executable, str(ROOT / "cases/run_case.py"), "periodic", "--scale", "demo", "--np", "2",
               "--mesh-tolerance", "20e-6", "--out", str(out), "--seed", str(seed), "-v", "screw_drive", drive,
               "-v", "rpm", str(rpm)]
    for name, value in RUN:
        command += ["-v", name, str(value)]
    proc = subprocess.run(command, capture_output=True, text=True, timeout=1200)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    by_zone = Run(out).element_averages().by_zone
    solid, axial = (np.array([e.mean for e in by_zone[name]]) for name in ("solid_fraction", "mean_axial_velocity"))
    return solid, axial


def disagreement(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|mean difference| / (t s_pooled √(2/n)) per element: ≤ 1 agrees."""
    n = a.shape[0]
    pooled = np.sqrt((a.var(axis=0, ddof=1) + b.var(axis=0, ddof=1)) / 2.0)
    return np.abs(a.mean(axis=0) - b.mean(axis=0)) / (T_CRITICAL * pooled * np.sqrt(2.0 / n))


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, list[tuple[np.ndarray, np.ndarray]]]:
    base = tmp_path_factory.mktemp("statistics")
    return {drive: [run_case(base / f"{drive}-{seed}", drive, seed) for seed in SEEDS]
            for drive in ("stock", "corotating")}


def test_element_statistics_agree_within_run_to_run_scatter(runs):
    for index, name in ((0, "solid fraction"), (1, "axial velocity")):
        stock = np.array([r[index] for r in runs["stock"]])
        corotating = np.array([r[index] for r in runs["corotating"]])
        ratio = disagreement(stock, corotating)
        print(f"{name}: stock {np.round(stock.mean(axis=0), 4)} corotating {np.round(corotating.mean(axis=0), 4)}")
        print(f"  seed-to-seed sd stock {np.round(stock.std(axis=0, ddof=1), 4)} corotating "
              f"{np.round(corotating.std(axis=0, ddof=1), 4)}; |difference| / allowed {np.round(ratio, 2)}")
        assert np.all(ratio <= 1.0), f"{name}: elements {np.where(ratio > 1.0)[0] + 1} differ beyond the scatter"


def test_the_criterion_detects_a_wrong_screw_speed(runs, tmp_path):
    """Power check: the corotating screws at 450 rpm instead of 600 must fail the same criterion."""
    slow = np.array([run_case(tmp_path / f"slow-{seed}", "corotating", seed, rpm=450)[1] for seed in SEEDS])
    stock = np.array([r[1] for r in runs["stock"]])
    ratio = disagreement(stock, slow)
    print(f"axial velocity at 450 rpm {np.round(slow.mean(axis=0), 4)}; |difference| / allowed {np.round(ratio, 2)}")
    assert np.any(ratio > 1.0)
