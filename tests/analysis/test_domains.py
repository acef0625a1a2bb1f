"""The periodic sub-domain against the full granulator (tsg_analysis.domains): the full run's
elements aligned on the first kneading element, the section's hold-up from the element masses, and
the time per passage of the kneading block from the residence records, each against a value
computed here from the fixture's construction (make_fixture)."""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import tsg_analysis.domains as domains

from make_fixture import DENSITY, ELEMENT_VALUES, FEED_KG_H, FREE_AREA, LAYOUTS, MEAN_RESIDENCE, write_run
from tsg_analysis.accuracy import SPEED
from tsg_analysis.domains import (KNEADING_BLOCK, RECORD_HORIZON, SECTION, SECTION_FLUX, TIME_BY_BALANCE, TIME_PER_PASSAGE,
                                  compare_domains, domains_markdown, machine_residence, passage_times, section_holdup,
                                  section_indices)
from tsg_analysis.model import AXIAL_VELOCITY, MASS_FLOW, SOLID_FRACTION
from tsg_analysis.run_files import AnalysisInputError, read_zones

ANALYSIS_DIR = Path(__file__).resolve().parents[2] / "analysis"
STEADY = 1.2   # make_fixture.STEADY_FROM: the elements are full from here on


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("domains")
    write_run(root / "full", kind="full", dumps=None, meshes=False, seed=7)
    for seed in (1, 2, 3):
        write_run(root / f"periodic-{seed}", kind="periodic", dumps=None, meshes=False, seed=seed)
    return root


def test_the_full_machines_section_is_found_on_its_first_kneading_block(runs):
    full, periodic = read_zones(runs / "full" / "zones.txt"), read_zones(runs / "periodic-1" / "zones.txt")
    # full: C(50) K1..K6 C(37.5) K7..K12 C(37.5) CH CH; periodic: C K1..K6 C
    assert section_indices(full, periodic) == [0, 1, 2, 3, 4, 5, 6, 7]


def test_section_holdup_scales_the_longer_conveying_elements_by_length(runs):
    periodic = read_zones(runs / "periodic-1" / "zones.txt")
    holdup = section_holdup(runs / "full", periodic, STEADY)
    # uniformly filled elements: the section holds what the periodic domain's own elements would,
    # each length x free area x solid fraction x density
    expected = sum(FREE_AREA * length * 1e-3 * ELEMENT_VALUES[kind][0] * DENSITY for kind, length in LAYOUTS["periodic"])
    assert holdup.mean == pytest.approx(expected, rel=1e-5)


def test_periodic_against_full_element_by_element(runs, monkeypatch):
    # the fixture's records are short against the times they close at (see the test of that below):
    # the records path is checked here without that guard
    monkeypatch.setattr(domains, "RECORD_HORIZON", 0.0)
    comparison = compare_domains(runs / "full", [runs / f"periodic-{s}" for s in (1, 2, 3)], STEADY, STEADY)
    rows = {(r.quantity, r.scope): r for r in comparison.rows}
    for quantity in (SOLID_FRACTION, SPEED, AXIAL_VELOCITY):   # the same element values in both fixtures
        assert all(not rows[(quantity, label)].difference.significant for label in ("C1", "K1", "K6", "C2"))
        assert rows[(quantity, "K3")].full.mean == pytest.approx(rows[(quantity, "K3")].periodic.mean, rel=1e-6)
    assert (MASS_FLOW, SECTION_FLUX) in rows
    # the fixture splits each residence time over the zones in proportion to length x (3 for kneading):
    # the kneading block's share is 3 x 37.5 mm of the whole weight of each layout
    def block_share(kind: str) -> float:
        weights = [length * (3.0 if k == "kneading" else 1.0) for k, length in LAYOUTS[kind]]
        return 3.0 * 37.5 / sum(weights)

    block = rows[(TIME_PER_PASSAGE, KNEADING_BLOCK)]
    assert block.full.mean == pytest.approx(MEAN_RESIDENCE * block_share("full"), rel=0.05)
    assert block.periodic.mean == pytest.approx(MEAN_RESIDENCE * block_share("periodic"), rel=0.05)
    assert block.difference.significant and block.difference.value > 0   # the periodic block holds a larger share
    (ks,) = [c for c in comparison.rtds if c.scope == KNEADING_BLOCK]
    assert not ks.agree and ks.mean_difference == pytest.approx(block_share("periodic") / block_share("full") - 1, rel=0.1)
    assert comparison.periodic_holdup == pytest.approx(comparison.holdup.mean, rel=1e-5)
    text = domains_markdown(comparison)
    assert "| time per passage (s) | kneading block |" in text and "KS distance" in text
    assert np.isfinite(comparison.holdup.half_width)


def test_mean_residence_time_of_the_full_machine_two_ways(runs):
    residence = machine_residence(runs / "full", STEADY)
    # the records: Gamma(TANKS, MEAN_RESIDENCE / TANKS) residence times of the particles that left
    assert residence.records.mean == pytest.approx(MEAN_RESIDENCE, rel=0.1)
    assert abs(residence.records.mean - MEAN_RESIDENCE) < 1.5 * residence.records.half_width
    # the mass balance: every element full from STEADY on, the outlet sensor at FEED_KG_H ± noise
    holdup = sum(FREE_AREA * length * 1e-3 * ELEMENT_VALUES[kind][0] * DENSITY for kind, length in LAYOUTS["full"])
    assert residence.holdup.mean == pytest.approx(holdup, rel=1e-5)
    assert abs(residence.outflow.mean - FEED_KG_H) < residence.outflow.half_width
    tau, half_width = residence.mass_balance()
    assert tau == pytest.approx(holdup / (FEED_KG_H / 3600), rel=0.01)
    assert 0 < half_width < 0.01 * tau
    assert "hold-up / throughput" in residence.text()


def test_mean_residence_time_needs_particles_leaving(runs):
    with pytest.raises(AnalysisInputError, match="left through the outlet after 5 s"):
        machine_residence(runs / "full", 5.0)


def test_the_command_line_writes_the_table_and_both_figures(runs, tmp_path):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ANALYSIS_DIR), os.environ.get("PYTHONPATH", "")]))
    command = [sys.executable, "-m", "tsg_analysis", "domains", str(runs / "full"), "--full-start", str(STEADY)]
    holdup_only = subprocess.run([*command, "--periodic-zones", str(runs / "periodic-1" / "zones.txt")],
                                 capture_output=True, text=True, env=env)
    assert holdup_only.returncode == 0, holdup_only.stderr
    assert "hold-up on the periodic domain's elements" in holdup_only.stdout
    assert "Mean residence time of the full granulator" in holdup_only.stdout
    periodic = ",".join(str(runs / f"periodic-{s}") for s in (1, 2, 3))
    full = subprocess.run([*command, "--periodic", periodic, "--periodic-start", str(STEADY), "--out", str(tmp_path)],
                          capture_output=True, text=True, env=env)
    assert full.returncode == 0, full.stderr
    assert "hold-up / throughput" in (tmp_path / "domains.md").read_text(encoding="utf-8")
    assert (tmp_path / "elements.png").stat().st_size > 10_000
    assert (tmp_path / "rtd.png").is_file()   # says why it is empty: the fixture's records are too short


def test_time_per_passage_by_mass_balance_over_the_periodic_lengths(runs):
    comparison = compare_domains(runs / "full", [runs / f"periodic-{s}" for s in (1, 2, 3)], STEADY, STEADY)
    rows = {(r.quantity, r.scope): r for r in comparison.rows}
    axial = {kind: values[2] for kind, values in ELEMENT_VALUES.items()}
    periodic = LAYOUTS["periodic"]
    # one element: its length over its (constant) axial velocity; the full machine's 37.5 mm
    # conveying element counts over the periodic domain's 29.167 mm, as the hold-up does
    assert rows[(TIME_BY_BALANCE, "K3")].full.mean == pytest.approx(6.25e-3 / axial["kneading"], rel=1e-6)
    for side in ("full", "periodic"):
        assert getattr(rows[(TIME_BY_BALANCE, "C1")], side).mean == pytest.approx(29.167e-3 / axial["conveying"], rel=1e-6)
    # the section: L Σ m / Σ m v_x, masses ∝ length × solid fraction (hold-up over the net flux)
    mass = [length * ELEMENT_VALUES[kind][0] for kind, length in periodic]
    expected = sum(length for _, length in periodic) * 1e-3 * sum(mass) / sum(m * axial[kind] for m, (kind, _) in zip(mass, periodic))
    assert rows[(TIME_BY_BALANCE, SECTION)].periodic.mean == pytest.approx(expected, rel=1e-6)
    assert rows[(TIME_BY_BALANCE, SECTION)].full.mean == pytest.approx(expected, rel=1e-5)   # the same elements


def test_records_too_short_against_their_closing_time_are_not_estimated(runs):
    # a periodic record closes when its pass of the domain does: the fixture's section takes 0.70 s by
    # mass balance, and RECORD_HORIZON x 0.70 s after the first entry is past the end of its 1 s record,
    # where only the fast passes would have completed
    comparison = compare_domains(runs / "full", [runs / f"periodic-{s}" for s in (1, 2, 3)], STEADY, STEADY)
    rows = {(r.quantity, r.scope) for r in comparison.rows}
    # the full fixture's records close at its outlet, hold-up / throughput ≈ 4.9 s after entry: also too short
    assert sorted(comparison.records_truncated) == sorted([*(str(runs / f"periodic-{s}") for s in (1, 2, 3)), "full"])
    assert comparison.records_truncated[str(runs / "periodic-1")] == f"{RECORD_HORIZON * 0.6942:.3g} s"
    assert not any(quantity == TIME_PER_PASSAGE for quantity, _ in rows) and comparison.rtds == []
    assert "too short a record in" in domains_markdown(comparison)
    # the same records without the horizon: the fast passes, a number that would be biased
    assert len(passage_times(runs / "periodic-1", range(8), STEADY)) > 0
    assert len(passage_times(runs / "periodic-1", range(8), STEADY, horizon=RECORD_HORIZON * 0.6942)) == 0


def test_a_side_with_records_is_reported_when_the_other_has_none(runs, monkeypatch):
    # half a closing time: past the full fixture's record end (4.9 s / 2), not the periodic's (0.69 s / 2)
    monkeypatch.setattr(domains, "RECORD_HORIZON", 0.5)
    comparison = compare_domains(runs / "full", [runs / f"periodic-{s}" for s in (1, 2, 3)], STEADY, STEADY)
    row = {(r.quantity, r.scope): r for r in comparison.rows}[(TIME_PER_PASSAGE, KNEADING_BLOCK)]
    assert np.isnan(row.full.mean) and np.isfinite(row.periodic.mean)
    assert not row.difference.significant
    assert list(comparison.records_truncated) == ["full"]
