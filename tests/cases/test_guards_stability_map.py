"""Smoke run of benchmarks/stability_map.py on a tiny window, and its bisection on a known answer."""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import stability_map  # noqa: E402


def test_bisection_brackets_a_known_threshold():
    threshold = 0.33
    calls = []

    def stable_at(fraction: float) -> bool:
        calls.append(fraction)
        return fraction < threshold

    low, high = stability_map.largest_stable(stable_at, [0.05, 0.1, 0.2, 0.4, 0.8], bisections=3)
    assert low < threshold < high
    assert high / low == pytest.approx(2 ** (1 / 8))   # three halvings of log(0.4/0.2)
    assert len(calls) == 5 + 3


def test_map_smoke_run_records_a_stable_and_an_unstable_step(tmp_path):
    assert stability_map.main(["--cases", "base", "--fractions", "0.1,3.2", "--bisections", "0",
                               "--window", "0.006", "--out", str(tmp_path)]) == 0
    result = json.loads((tmp_path / "stability_map.json").read_text())
    runs = {run["fraction"]: run for run in result["runs"]}
    # the estimate check/contact prints is the Rayleigh time of the 1 mm paracetamol particles
    # (materials.in: G 1.7e7 Pa, ν 0.25, ρ 1263 kg/m^3), computed here independently
    rayleigh = math.pi * 0.0005 * math.sqrt(1263 / 1.7e7) / (0.1631 * 0.25 + 0.8766)
    assert runs[0.1]["estimate"] == pytest.approx(rayleigh, rel=1e-3)
    assert runs[0.1]["timestep"] == pytest.approx(0.1 * rayleigh, rel=1e-3)
    assert runs[0.1]["stable"] and runs[0.1]["particles"] > 50
    assert 0 < runs[0.1]["max_pair_overlap"] < 0.1
    assert 0 < max(runs[0.1]["max_wall_overlap"].values()) < 0.1
    # three times the Rayleigh time blows up, and the guard says so
    assert not runs[3.2]["stable"] and runs[3.2]["reason"] == "kinetic-energy blow-up"
    assert result["summary"][0]["largest_stable_fraction"] == 0.1
    assert (tmp_path / "stability_map.md").read_text(encoding="utf-8").startswith("| case |")
    assert (tmp_path / "stability_map.png").stat().st_size > 1000
