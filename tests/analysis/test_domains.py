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
from tsg_analysis.domains import (CONVEYING, KNEADING_BLOCK, RECORD_HORIZON, SECTION, SECTION_FLUX, TIME_BY_BALANCE, TIME_PER_PASSAGE,
                                  compare_domains, domains_markdown, machine_residence, passage_times, section_holdup,
                                  section_indices)
from tsg_analysis.model import AXIAL_VELOCITY, MASS_FLOW, SOLID_FRACTION, SPEED
from tsg_analysis.run import Run
from tsg_analysis.run_files import AnalysisInputError

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
    full, periodic = Run(runs / "full").zones, Run(runs / "periodic-1").zones
    # full: C(50) K1..K6 C(37.5) K7..K12 C(37.5) CH CH; periodic: C K1..K6 C
    assert section_indices(full, periodic) == [0, 1, 2, 3, 4, 5, 6, 7]


def test_section_holdup_scales_the_longer_conveying_elements_by_length(runs):
    periodic = Run(runs / "periodic-1").zones
    holdup = section_holdup(Run(runs / "full"), periodic, STEADY)
    # uniformly filled elements: the section holds what the periodic domain's own elements would,
    # each length x free area x solid fraction x density
    expected = sum(FREE_AREA * length * 1e-3 * ELEMENT_VALUES[kind][0] * DENSITY for kind, length in LAYOUTS["periodic"])
    assert holdup.mean == pytest.approx(expected, rel=1e-5)


def test_periodic_against_full_element_by_element(runs, monkeypatch):
    # the fixture's records are short against the times they close at (see the test of that below):
    # the records path is checked here without that guard
    monkeypatch.setattr(domains, "RECORD_HORIZON", 0.0)
    comparison = compare_domains(Run(runs / "full"), [Run(runs / f"periodic-{s}") for s in (1, 2, 3)], STEADY, STEADY)
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
    assert ks.ks_p_value < 1e-6   # thousands of passes: a shift of this size is resolved
    assert {c.scope for c in comparison.rtds} == {CONVEYING, KNEADING_BLOCK, SECTION}   # seed Fig. 8's panels
    assert comparison.periodic_holdup == pytest.approx(comparison.holdup.mean, rel=1e-5)
    text = domains_markdown(comparison)
    assert "| time per passage (s) | kneading block |" in text and "KS distance" in text
    assert np.isfinite(comparison.holdup.half_width)


def test_mean_residence_time_of_the_full_machine_two_ways(runs):
    residence = machine_residence(Run(runs / "full"), STEADY)
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
        machine_residence(Run(runs / "full"), 5.0)


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
    comparison = compare_domains(Run(runs / "full"), [Run(runs / f"periodic-{s}") for s in (1, 2, 3)], STEADY, STEADY)
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
    comparison = compare_domains(Run(runs / "full"), [Run(runs / f"periodic-{s}") for s in (1, 2, 3)], STEADY, STEADY)
    rows = {(r.quantity, r.scope) for r in comparison.rows}
    # the full fixture's passes count from RECORD_HORIZON x 0.69 s after its steady start, past its end
    assert sorted(comparison.records_truncated) == sorted([*(str(runs / f"periodic-{s}") for s in (1, 2, 3)), "full"])
    assert f"end before {RECORD_HORIZON * 0.6942:.3g} s after its first entry" in comparison.records_truncated[str(runs / "periodic-1")]
    assert f"between {STEADY + RECORD_HORIZON * 0.6942:.3g} s" in comparison.records_truncated["full"]
    assert not any(quantity == TIME_PER_PASSAGE for quantity, _ in rows) and comparison.rtds == []
    assert "no passes counted for" in domains_markdown(comparison)
    # the same records without the horizon: the fast passes, a number that would be biased
    assert len(passage_times(Run(runs / "periodic-1"), range(8), STEADY)) > 0
    assert len(passage_times(Run(runs / "periodic-1"), range(8), STEADY, horizon=RECORD_HORIZON * 0.6942)) == 0


def test_a_side_with_records_is_reported_when_the_other_has_none(runs, monkeypatch):
    # two balance times of the section (0.69 s): after the periodic fixtures' first entries (0 s) within
    # their records (to 2 s), after the full fixture's steady start (1.2 s) past them
    monkeypatch.setattr(domains, "RECORD_HORIZON", 2.0)
    comparison = compare_domains(Run(runs / "full"), [Run(runs / f"periodic-{s}") for s in (1, 2, 3)], STEADY, STEADY)
    row = {(r.quantity, r.scope): r for r in comparison.rows}[(TIME_PER_PASSAGE, KNEADING_BLOCK)]
    assert np.isnan(row.full.mean) and np.isfinite(row.periodic.mean)
    assert not row.difference.significant
    assert list(comparison.records_truncated) == ["full"]


# ---- the full run's steady start: a filling that lasts more than half the record -----------------

def _filling(rng: np.random.Generator, blocks: int, fill_share: float, plateau: float = 3.8e-3,
             noise: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """Hold-up that grows linearly over the first fill_share of the record, then stays at `plateau`
    with AR(1) noise (correlation 0.8 between blocks); one block per 10 ms."""
    times = 0.01 * np.arange(1, blocks + 1)
    end = fill_share * times[-1]
    noise_series = np.zeros(blocks)
    for k in range(1, blocks):
        noise_series[k] = 0.8 * noise_series[k - 1] + rng.normal(0.0, noise * plateau * 0.6)
    return times, plateau * np.minimum(times / end, 1.0) + noise_series, end


def test_the_steady_start_of_a_filling_run_is_found_past_its_first_half():
    rng = np.random.default_rng(5)
    times, holdup, filled = _filling(rng, 1500, 0.6)
    flux = holdup * 1e3 + rng.normal(0.0, 0.1, len(times))   # flux follows the hold-up
    start = domains.filling_steady_start(holdup, flux, times)
    # the hold-up is full at `filled` (9 s of 15): the start is near it (the top of the ramp is within
    # the noise), and not far after
    assert filled - 0.9 <= start <= filled + 1.5, (start, filled)
    # what the first-half search of the periodic runs (validation.steady_start) would pick: inside the filling
    from tsg_analysis.uncertainty import detect_start
    assert detect_start(holdup, times, within=0.5) < filled - 1.0


def test_the_later_of_hold_up_and_flux_starts():
    rng = np.random.default_rng(6)
    times, holdup, filled = _filling(rng, 1500, 0.3)
    _, flux, flux_filled = _filling(rng, 1500, 0.55, plateau=4.0)
    start = domains.filling_steady_start(holdup, flux, times)
    assert flux_filled - 0.9 <= start <= flux_filled + 1.5, (start, flux_filled)


def test_a_run_still_filling_is_refused():
    rng = np.random.default_rng(7)
    for fill_share in (1.5, 0.99):   # two thirds full at the end of the record; full for its last 0.15 s
        times, holdup, _ = _filling(rng, 1500, fill_share)
        with pytest.raises(ValueError, match=r"independent samples of the hold-up .*run it longer"):
            domains.filling_steady_start(holdup, holdup * 1e3, times)


def test_a_hold_up_that_creeps_is_refused():
    # no start-up to detect (white noise about a line), but 10 % more at the end than at the start:
    # the two halves of the window differ
    rng = np.random.default_rng(8)
    times = 0.01 * np.arange(1, 1501)
    holdup = 3.8e-3 * (1.0 + 0.1 * times / times[-1]) + rng.normal(0.0, 0.02 * 3.8e-3, len(times))
    with pytest.raises(ValueError, match=r"still changes: .* in its first half, .* in its second"):
        domains.filling_steady_start(holdup, holdup * 1e3, times)
    flat = 3.8e-3 + rng.normal(0.0, 0.02 * 3.8e-3, len(times))   # the same without the creep: accepted
    assert domains.filling_steady_start(flat, flat * 1e3, times) < 0.5 * times[-1]


def test_auto_full_start_names_the_run_when_it_refuses(runs, monkeypatch):
    periodic = Run(runs / "periodic-1").zones
    monkeypatch.setattr(domains, "MIN_INDEPENDENT", 1e9)   # no record is long enough for this
    with pytest.raises(AnalysisInputError, match="no steady window on the periodic domain's section"):
        domains.full_steady_start(Run(runs / "full"), periodic)


# ---- the full run's passes of the section: outlet records and the snapshot of those still inside ------

SECTION_MEAN = 2.0   # s, Gamma(3) time in the section (zones 2-6 below)
DOWNSTREAM_MEAN = 6.0  # s, downstream: long against the window, as in the demo's full run
SNAPSHOT = 20.0      # s


def _write_machine(run_dir: Path, rng: np.random.Generator, particles: int = 20_000) -> dict[str, np.ndarray]:
    """A full machine fed at a constant rate from t = 0: a particle spends a Gamma time upstream (zone 1),
    in the section (zones 2-6, fixed shares) and a time downstream (zone 7) that grows with its time
    in the section, in that order. Records as
    fix residence/time writes them with inside_records 1: an outlet record per particle that left by
    SNAPSHOT, an inside record with the zones' times so far per particle still inside."""
    run_dir.mkdir(parents=True)
    edges = np.array([0.0, 0.05, 0.09, 0.1, 0.11, 0.12, 0.16, 0.4])
    kinds = ["conveying", "conveying", "kneading", "kneading", "kneading", "conveying", "conveying"]
    (run_dir / "zones.txt").write_text("# index type x_start_m x_end_m free_volume_m3\n" + "".join(
        f"{i + 1} {kind} {edges[i]:.6f} {edges[i + 1]:.6f} 1e-5\n" for i, kind in enumerate(kinds)))
    entry = np.sort(rng.uniform(0.0, SNAPSHOT, particles))
    upstream = rng.gamma(4.0, 0.5 / 4.0, particles)
    section = rng.gamma(3.0, SECTION_MEAN / 3.0, particles)
    # slow in the section, slow downstream (as the demo's slow particles under the flight tips)
    downstream = DOWNSTREAM_MEAN / SECTION_MEAN * section * rng.gamma(4.0, 1.0 / 4.0, particles)
    shares = np.array([0.3, 0.1, 0.15, 0.15, 0.3])
    whole = np.column_stack([upstream, section[:, None] * shares, downstream])
    elapsed = np.minimum(SNAPSHOT - entry, whole.sum(axis=1))
    before = np.cumsum(whole, axis=1) - whole
    by_zone = np.clip(elapsed[:, None] - before, 0.0, whole)
    left = entry + whole.sum(axis=1) <= SNAPSHOT
    by_type = [by_zone[:, np.array(kinds) == t].sum(axis=1) for t in ("conveying", "kneading", "chopping")]
    lines = ["# tsg-dem residence records v1", "# synthetic full machine (test_domains.py)",
             "# columns: id entry_time exit_time residence_time exit_reason time_conveying time_kneading "
             "time_chopping " + " ".join(f"time_zone_{i}" for i in range(1, 8))]
    for k in np.argsort(np.where(left, entry + elapsed, SNAPSHOT), kind="stable"):
        numbers = " ".join(f"{v:.12g}" for v in (*[b[k] for b in by_type], *by_zone[k]))
        lines.append(f"{k + 1} {entry[k]:.12g} {entry[k] + elapsed[k]:.12g} {elapsed[k]:.12g} "
                     f"{'outlet' if left[k] else 'inside'} {numbers}")
    (run_dir / "residence.txt").write_text("\n".join(lines) + "\n")
    return {"entry": entry, "section": section, "section_exit": entry + upstream + section, "left": left}


def test_full_passes_are_every_pass_that_ended_in_the_window(tmp_path):
    from scipy import stats

    from tsg_analysis.domains import full_passes
    truth = _write_machine(tmp_path / "machine", np.random.default_rng(11))
    after = 10.0   # the passes that end from here on began well after the feed started
    passes = full_passes(Run(tmp_path / "machine"), 5, after)
    ended = (truth["section_exit"] > after) & (truth["section_exit"] <= SNAPSHOT)
    assert passes.snapshot == SNAPSHOT and len(passes.exit_time) == np.count_nonzero(ended) > 3000
    np.testing.assert_allclose(passes.exit_time, np.sort(truth["section_exit"][ended]), rtol=0, atol=1e-9)
    times = passes.time_by_zone[:, 1:6].sum(axis=1)
    # the times of passes ending in a stationary window are distributed as the time per pass itself
    assert stats.kstest(times, stats.gamma(3.0, scale=SECTION_MEAN / 3.0).cdf).pvalue > 0.01
    assert abs(times.mean() - SECTION_MEAN) < 3 * times.std() / np.sqrt(len(times))
    # the outlet records alone miss the passes of particles still downstream: they lean to fast passes
    records = Run(tmp_path / "machine").residence
    outlet = records.exit_reason == "outlet"
    exits = records.entry_time + records.time_by_zone[:, :6].sum(axis=1)
    naive = records.time_by_zone[outlet & (exits > after)][:, 1:6].sum(axis=1)
    assert naive.mean() < SECTION_MEAN - 5 * naive.std() / np.sqrt(len(naive))


def test_full_passes_need_a_snapshot_and_stop_at_it(tmp_path):
    from tsg_analysis.domains import full_passes
    _write_machine(tmp_path / "machine", np.random.default_rng(12), particles=2000)
    residence = tmp_path / "machine" / "residence.txt"
    text = residence.read_text()
    count = len(full_passes(Run(tmp_path / "machine"), 5, 10.0).exit_time)
    # a run continued past its snapshot without a new one: later outlet records are not passes of the window
    later = "99999 15 23 8 outlet 8 0 0 1 1 0 0 1 1 4\n"
    residence.write_text(text + later)
    assert len(full_passes(Run(tmp_path / "machine"), 5, 10.0).exit_time) == count
    residence.write_text("\n".join(l for l in text.splitlines() if " inside " not in l) + "\n")
    with pytest.raises(AnalysisInputError, match="inside_records 1"):
        full_passes(Run(tmp_path / "machine"), 5, 10.0)


def test_full_record_times_cover_the_part_of_each_element_the_periodic_records_count(runs, tmp_path, monkeypatch):
    # periodic records do not count the buffers at the ends of their domain (6.25 mm of each conveying
    # element, 29.167 mm long): the full run's times are scaled to the same 22.917 mm
    import shutil
    monkeypatch.setattr(domains, "RECORD_HORIZON", 0.0)
    periodic = []
    for seed in (1, 2, 3):
        copy = tmp_path / f"periodic-{seed}"
        shutil.copytree(runs / f"periodic-{seed}", copy)
        lines = (copy / "residence.txt").read_text().splitlines()
        lines.insert(1, "# analysis domain: [0.00625, 0.0895833)")
        (copy / "residence.txt").write_text("\n".join(lines) + "\n")
        periodic.append(copy)
    assert Run(periodic[0]).residence.analysis_domain == (0.00625, 0.0895833)
    whole = compare_domains(Run(runs / "full"), [Run(runs / f"periodic-{s}") for s in (1, 2, 3)], STEADY, STEADY)
    buffered = compare_domains(Run(runs / "full"), [Run(d) for d in periodic], STEADY, STEADY)
    np.testing.assert_allclose(buffered.samples["full"][CONVEYING], whole.samples["full"][CONVEYING] * (22.917 / 29.167),
                               rtol=2e-4)
    np.testing.assert_array_equal(buffered.samples["full"][KNEADING_BLOCK], whole.samples["full"][KNEADING_BLOCK])
    np.testing.assert_array_equal(buffered.samples["periodic"][SECTION], whole.samples["periodic"][SECTION])
    lines = (periodic[2] / "residence.txt").read_text().replace("[0.00625, 0.0895833)", "[0.005, 0.0908)")
    (periodic[2] / "residence.txt").write_text(lines)
    with pytest.raises(AnalysisInputError, match="different analysis domains"):
        compare_domains(Run(runs / "full"), [Run(d) for d in periodic], STEADY, STEADY)
