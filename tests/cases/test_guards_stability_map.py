"""Smoke run of benchmarks/stability_map.py on a tiny window, and its bisection on a known answer."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import stability_map   # benchmarks/ is on PYTHONPATH (tests/CMakeLists.txt)


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


def test_a_stable_rung_above_an_unstable_one_does_not_count_and_the_floor_is_tried():
    # 0.1 fails (a squeeze failure, say) while 0.2 and 0.4 pass: the edge is below 0.1
    assert stability_map.largest_stable(lambda f: f not in (0.1, 0.8), [0.05, 0.1, 0.2, 0.4, 0.8], 0) == (0.05, 0.1)
    # every rung fails: halved rungs down to the floor, then bisection towards the smallest failure
    calls = []

    def stable_at(fraction: float) -> bool:
        calls.append(fraction)
        return fraction < 0.02

    low, high = stability_map.largest_stable(stable_at, [0.05, 0.1], bisections=1, floor=0.0125)
    assert calls[:4] == [0.05, 0.1, 0.025, 0.0125]
    assert (low, high) == (pytest.approx(math.sqrt(0.0125 * 0.025)), 0.025)
    low, high = stability_map.largest_stable(lambda f: False, [0.05, 0.1], bisections=2, floor=0.0125)
    assert math.isnan(low) and high == 0.0125


def test_the_paddle_is_closed_with_outward_normals_and_its_tips_keep_the_clearance():
    profile = stability_map.paddle_profile(0.0003)
    outline = stability_map.paddle_outline(profile)
    y, z = outline[:, 0], outline[:, 1]
    assert 0.5 * np.sum(y * np.roll(z, -1) - np.roll(y, -1) * z) > 0   # counter-clockwise: outward normals
    assert np.hypot(y, z).max() == pytest.approx(stability_map.BARREL_RADIUS - 0.0003, rel=1e-12)
    assert np.hypot(y, z).min() == pytest.approx(stability_map.ROOT_RADIUS, rel=1e-12)
    sites = stability_map.fill_positions(0.001, 0.0, 0.0003)
    u, v = sites[:, 2], -sites[:, 1]
    assert (np.hypot(u, v) > profile.radius(np.arctan2(v, u))).all()   # every particle outside the paddle
    assert (np.hypot(sites[:, 1], sites[:, 2]) < stability_map.BARREL_RADIUS - 0.5e-3).all()
    assert ((sites[:, 0] >= 0) & (sites[:, 0] < stability_map.SLICE_LENGTH)).all()   # none dropped by lmp


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
    assert runs[0.1]["stable"] and runs[0.1]["particles"] == len(stability_map.fill_positions(0.001, 0.0, 0.00044))
    assert 0 <= runs[0.1]["max_pair_overlap"] < 0.1
    assert 0 < max(runs[0.1]["max_wall_overlap"].values()) < 0.1
    # the base clearance (0.44 mm) is narrower than its 1 mm particles: a squeeze case, whose speed
    # guard is off; three times the Rayleigh time blows up, and the ledger's energy budget says so
    assert runs[0.1]["squeeze"] and runs[0.1]["gap_ratio"] == pytest.approx(0.44)
    assert not runs[3.2]["stable"] and runs[3.2]["reason"] == "energy runaway"
    assert runs[3.2]["ledger"]["max_energy_excess"] > 0.05
    assert result["summary"][0]["largest_stable_fraction"] == 0.1
    assert (tmp_path / "stability_map.md").read_text(encoding="utf-8").startswith("| case |")
    assert (tmp_path / "stability_map.png").stat().st_size > 1000


def test_the_ledger_counts_squeezes_below_the_particle_size_and_none_at_the_demo_clearance(tmp_path):
    assert stability_map.main(["--cases", "gap-0.8,gap-1.2", "--fractions", "0.05", "--bisections", "0",
                               "--window", "0.025", "--out", str(tmp_path)]) == 0
    runs = {run["case"]: run for run in json.loads((tmp_path / "stability_map.json").read_text())["runs"]}
    squeeze, passing = runs["gap-0.8"], runs["gap-1.2"]
    # 0.8 mm under 1 mm particles: squeezed between a paddle tip and the barrel, counted, not stopped
    assert squeeze["squeeze"] and squeeze["stable"]
    assert squeeze["ledger"]["events"] > 0 and squeeze["ledger"]["events_per_s"] > 0
    assert squeeze["ledger"]["peak_wall"] > 0.1 and squeeze["ledger"]["max_release_speed"] > 0
    assert squeeze["ledger"]["crossings"] == 0
    # 1.2 x the particle: they pass, with the cases' overlap and speed guards on
    assert not passing["squeeze"] and passing["stable"]
    assert passing["ledger"]["events"] == 0 and passing["ledger"]["open"] == 0
    assert passing["ledger"]["crossings"] == 0 and max(passing["max_wall_overlap"].values()) < 0.1
