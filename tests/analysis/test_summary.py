"""The runner's summary and the sweep tables: every number ± 95 % interval, differences marked
significant only when their interval excludes zero; the main job's too-short window says so."""
import shutil

import numpy as np
import pytest

from make_fixture import DENSITY, ELEMENT_VALUES, FEED_KG_H, FREE_AREA, LAYOUTS, write_short_run
from tsg_analysis.model import Settings
from tsg_analysis.report import build_report
from tsg_analysis.run import Run
from tsg_analysis.summary import (AXIAL_VELOCITY, MASS_FLOW, RESIDENCE_HOLDUP, RESIDENCE_RECORDS, SOLID_FRACTION,
                                  SPEED, compare_runs, summarise, summary_table, sweep_markdown, write_sweep_csv)


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    path = tmp_path_factory.mktemp("runs") / "periodic-demo"
    write_short_run(path)
    return path


def test_summary_of_a_steady_run(periodic_run):
    summary = summarise(Run(periodic_run[0]))
    inlet = summary.get(MASS_FLOW, "sensor_1")
    assert inlet.resolved and abs(inlet.mean - FEED_KG_H) <= inlet.half_width
    # the fixture's elements are half full until 1.2 s: 19 of 100 blocks at 0.15, 81 at 0.3
    kneading = summary.get(SOLID_FRACTION, "K1")
    assert kneading.mean == pytest.approx((19 * 0.15 + 81 * 0.3) / 100)
    assert kneading.detected_start == pytest.approx(1.2, abs=0.011)  # the step, found
    assert summary.get(SPEED, "K1").mean == pytest.approx(ELEMENT_VALUES["kneading"][1])  # the fixture's |v|, constant
    assert summary.get(SPEED, "C1").mean == pytest.approx(ELEMENT_VALUES["conveying"][1])
    assert summary.get(RESIDENCE_RECORDS, "total").resolved and summary.complete_records > 1000
    assert {r.quantity for r in summary.rows} == {MASS_FLOW, RESIDENCE_RECORDS, RESIDENCE_HOLDUP, SOLID_FRACTION,
                                                  AXIAL_VELOCITY, SPEED}
    assert summary.parameters.rpm == 600.0
    text = summary_table(Run(periodic_run[0]))
    assert "± " in text and "600 rpm" in text and "mass flow (kg/h)" in text


def test_summary_from_a_start_time_leaves_the_start_up_out(periodic_run):
    """From 1.2 s on the fixture's elements are full: only the blocks that begin at or after the
    start count (their intervals are 0.01 s long), and the inlet sensor still gives the feed rate."""
    summary = summarise(Run(periodic_run[0]), 1.2)
    kneading = summary.get(SOLID_FRACTION, "K1")
    assert kneading.mean == pytest.approx(0.3) and kneading.samples == 80
    # each element's residence time by Little's law, τ_e = m_e / Q with Q = Σ m v_x / L, from the
    # fixture's constant masses and axial velocities (its elements.txt rounds to 6 digits)
    lengths = [length * 1e-3 for _, length in LAYOUTS["periodic"]]
    masses = [FREE_AREA * length * ELEMENT_VALUES[kind][0] * DENSITY for (kind, _), length in zip(LAYOUTS["periodic"], lengths)]
    flux = sum(m * ELEMENT_VALUES[kind][2] for m, (kind, _) in zip(masses, LAYOUTS["periodic"])) / sum(lengths)
    assert summary.get(RESIDENCE_HOLDUP, "K1").mean == pytest.approx(masses[1] / flux, rel=1e-4)
    assert summary.get(RESIDENCE_HOLDUP, "C2").mean == pytest.approx(masses[-1] / flux, rel=1e-4)
    inlet = summary.get(MASS_FLOW, "sensor_1")
    assert inlet.chosen_start > 1.2 and abs(inlet.mean - FEED_KG_H) <= inlet.half_width
    assert summary.complete_records < summarise(Run(periodic_run[0])).complete_records


def test_the_main_jobs_short_window_says_so_with_the_interval(short_run, tmp_path):
    summary = summarise(Run(short_run))
    assert summary.complete_records == 0
    assert all(not r.estimate.resolved for r in summary.rows), [r for r in summary.rows if r.estimate.resolved]
    text = summary_table(Run(short_run))
    assert "0 complete records" in text and "shorter than one pass" in text
    assert "window too short: too few independent samples" in text and "indicative" in text
    report = build_report([short_run], tmp_path, settings=Settings(snapshot=False))
    markdown = (tmp_path / "report.md").read_text(encoding="utf-8")
    assert report.runs[0].transient and report.runs[0].profile is not None
    assert "### Element profiles" in markdown and "window too short (" in markdown
    assert "shorter than one pass" in markdown  # no RTD, and why
    assert (tmp_path / "periodic-demo_massflow.png").stat().st_size > 10_000


def test_sweep_table_replicas_and_significance(tmp_path, periodic_run):
    from make_fixture import write_run

    replica = tmp_path / "replica"
    write_run(replica, kind="periodic", dumps=None, meshes=False, seed=11)
    faster = tmp_path / "faster"
    shutil.copytree(replica, faster)
    lines = (faster / "massflow.txt").read_text().splitlines()
    shifted = [line if line.startswith("#") else " ".join(line.split()[:2] + [f"{float(w) + 1.0:.5f}"
                                                                             for w in line.split()[2:]])
               for line in lines]
    (faster / "massflow.txt").write_text("\n".join(shifted) + "\n")  # +1 kg/h at every sensor

    rows = compare_runs([Run(periodic_run[0])], {"replica": [Run(replica)], "faster": [Run(faster)],
                                             "both": [Run(replica), Run(faster)]})
    by_key = {(r.variant, r.quantity, r.scope): r for r in rows}
    same = by_key[("replica", MASS_FLOW, "sensor_1")].difference
    assert not same.significant and same.text("kg/h").startswith("not resolved")
    shift = by_key[("faster", MASS_FLOW, "sensor_1")].difference
    assert shift.significant and abs(shift.value - 1.0) <= shift.half_width
    assert not by_key[("faster", SOLID_FRACTION, "K1")].difference.significant  # elements.txt untouched
    assert by_key[("both", MASS_FLOW, "sensor_1")].value.replicas == 2
    # two replicas 1 kg/h apart: the Birge ratio widens the combined interval to cover the scatter
    assert by_key[("both", MASS_FLOW, "sensor_1")].value.half_width > 0.3
    table = sweep_markdown(rows)
    assert "| faster | mass flow (kg/h) | sensor_1 |" in table and "(significant) | yes |" in table
    write_sweep_csv(rows, tmp_path / "sweep.csv")
    data = np.genfromtxt(tmp_path / "sweep.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert len(data) == len(rows)


def test_compare_command_line_with_replicas(tmp_path, periodic_run, full_run):
    import os
    import subprocess
    import sys
    from pathlib import Path

    analysis = Path(__file__).resolve().parents[2] / "analysis"
    csv_path = tmp_path / "sweep.csv"
    proc = subprocess.run([sys.executable, "-m", "tsg_analysis", "compare", str(periodic_run[0]),
                           f"{periodic_run[0]},{full_run[0]}", "--csv", str(csv_path)],
                          capture_output=True, encoding="utf-8", env=dict(os.environ, PYTHONPATH=str(analysis)))
    assert proc.returncode == 0, proc.stderr
    assert "| variant | quantity |" in proc.stdout and f"{periodic_run[0]},{full_run[0]}" in proc.stdout
    assert csv_path.is_file() and "Traceback" not in proc.stderr


def test_compare_command_line_window(tmp_path, periodic_run, unsteady_run):
    """--start T analyses every run from T s on: the CLI's table is compare_runs(..., start=T), and on a
    drifting run it differs from the whole record's."""
    import csv
    import os
    import subprocess
    import sys
    from pathlib import Path

    analysis = Path(__file__).resolve().parents[2] / "analysis"

    def variant_means(*options: str) -> dict[tuple[str, str], float]:
        csv_path = tmp_path / "window.csv"
        proc = subprocess.run([sys.executable, "-m", "tsg_analysis", "compare", str(periodic_run[0]), str(unsteady_run[0]),
                               "--csv", str(csv_path), *options], capture_output=True, encoding="utf-8",
                              env=dict(os.environ, PYTHONPATH=str(analysis)))
        assert proc.returncode == 0, proc.stderr
        if options[:1] == ("--start",):
            assert f"every run from t = {float(options[1]):.4g} s" in proc.stdout
        with open(csv_path, encoding="utf-8") as stream:
            return {(row["quantity"], row["scope"]): float(row["variant_mean"]) for row in csv.DictReader(stream)}

    begins, _ = Run(unsteady_run[0]).block_times
    start = float(begins[len(begins) // 2])
    windowed, whole = variant_means("--start", f"{start}"), variant_means()
    expected = {(r.quantity, r.scope): r.value.mean
                for r in compare_runs([Run(periodic_run[0])], {"u": [Run(unsteady_run[0])]}, start)}
    assert windowed.keys() == expected.keys()
    for key, mean in expected.items():
        assert windowed[key] == pytest.approx(mean, rel=1e-9, abs=1e-12)
    assert any(abs(windowed[key] - whole[key]) > 1e-6 * max(1.0, abs(whole[key])) for key in windowed)

    # --end T: every run up to T s (runs of different lengths over one window); the first half of the
    # drifting run, which differs from its second half above
    early = variant_means("--end", f"{start}")
    expected_early = {(r.quantity, r.scope): r.value.mean
                      for r in compare_runs([Run(periodic_run[0])], {"u": [Run(unsteady_run[0])]}, None, start)}
    assert early.keys() == expected_early.keys()
    for key, mean in expected_early.items():
        assert early[key] == pytest.approx(mean, rel=1e-9, abs=1e-12)
    assert any(abs(early[key] - windowed[key]) > 1e-6 * max(1.0, abs(windowed[key])) for key in early)


def test_contact_health_reads_the_guards_columns(tmp_path):
    """The squeeze releases counted by check/contact (cumulative: the largest value), the largest
    wall overlap over the three meshes and the largest speed, over every thermo block."""
    from tsg_analysis.summary import contact_health

    header = "Step Time Atoms KinEng pp_max dt_ratio speed pg_scr1 pg_scr2 pg_bar fast escaped CPU\n"
    log = ("LIGGGHTS\n" + header + "0 0 10 0 0 0.1 1.0 0.01 0.02 0.03 0 0 0\n2000 0.001 10 0 0 0.1 9.5 0.2 0.1 0.05 3 0 1\n"
           "Loop time of 1 on 1 procs\n" + header + "4000 0.002 10 0 0 0.1 2.0 0.05 0.3 0.05 5 0 2\nLoop time of 1\n")
    (tmp_path / "log.lammps").write_text(log)
    assert contact_health(Run(tmp_path)) == ("contacts over the run: 5 squeeze releases (particles faster than "
                                        "guard_fast_speed, counted), largest wall overlap/R 0.3, largest speed 9.5 m/s")
    # with the squeeze ledger's crossing count (cumulative): named when a centre went behind a wall
    crossing = "Step Time Atoms speed pg_scr1 fast crossed\n"
    (tmp_path / "log.lammps").write_text("LIGGGHTS\n" + crossing + "0 0 10 1.0 0.1 0 0\n500 0.001 10 2.0 0.9 4 2\n"
                                         "Loop time of 1\n")
    assert contact_health(Run(tmp_path)) == ("contacts over the run: 4 squeeze releases (particles faster than "
                                        "guard_fast_speed, counted), largest wall overlap/R 0.9, largest speed 2 m/s, "
                                        "2 wall crossings (particle centres behind a screw or barrel surface: "
                                        "log.lammps names each)")
    (tmp_path / "log.lammps").write_text("LIGGGHTS\n" + crossing + "0 0 10 1.0 0.1 0 0\nLoop time of 1\n")
    assert contact_health(Run(tmp_path)).endswith("largest speed 1 m/s, 0 wall crossings")
    # a run made in segments: the earlier segments' logs count too (the largest overlap was in one)
    (tmp_path / "log.upto-500.lammps").write_text("LIGGGHTS\n" + crossing + "0 0 10 3.0 0.7 2 0\nLoop time of 1\n")
    (tmp_path / "log.upto-50.lammps").write_text("LIGGGHTS\n" + crossing + "0 0 10 1.0 0.95 1 0\nLoop time of 1\n")
    assert contact_health(Run(tmp_path)) == ("contacts over the run: 2 squeeze releases (particles faster than "
                                        "guard_fast_speed, counted), largest wall overlap/R 0.95, largest speed 3 m/s, "
                                        "0 wall crossings")
    for earlier in tmp_path.glob("log.upto-*.lammps"):
        earlier.unlink()
    (tmp_path / "log.lammps").write_text("LIGGGHTS\nStep Time Atoms\n0 0 10\nLoop time of 1\n")
    assert contact_health(Run(tmp_path)) is None


def test_report_summary_and_accuracy_give_the_same_number_for_one_window(periodic_run, tmp_path):
    """One run, one window (the report's detected steady start): the report, the summary and the
    accuracy tool's key quantities are one number each, to the last digit (they all ask tsg_analysis.Run)."""
    report = build_report([periodic_run[0]], tmp_path, settings=Settings(snapshot=False))
    analysed = report.runs[0]
    assert not analysed.transient and analysed.window is not None
    start = analysed.window[0]
    from_report = analysed.estimates()
    summary = summarise(Run(periodic_run[0]), start)
    key = Run(periodic_run[0]).key_estimates(start=start)
    keys = [(MASS_FLOW, "domain flux Σ m v_x / L"), (SOLID_FRACTION, "K1"), (AXIAL_VELOCITY, "K1"), (SPEED, "K1"),
            (RESIDENCE_RECORDS, "total")]
    for quantity, scope in keys:
        a, b, c = from_report[(quantity, scope)], summary.get(quantity, scope), key[(quantity, scope)]
        assert a.mean == b.mean == c.mean and a.half_width == b.half_width == c.half_width, (quantity, scope)
        assert a.samples == b.samples == c.samples > 0
    for (quantity, scope), e in from_report.items():   # every quantity the two share
        assert summary.get(quantity, scope) == e, (quantity, scope)
