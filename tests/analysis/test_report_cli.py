"""The CLI writes every figure, the JSON and the CSVs for a fixture; bad input gives a report that
says what could not be produced instead of a crash."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from make_fixture import MEAN_RESIDENCE, STEADY_FROM
from tsg_analysis.report import Settings, build_report

ANALYSIS_DIR = Path(__file__).resolve().parents[2] / "analysis"
RUN_FIGURES = ("massflow", "rtd", "cross_sections", "plane_flows", "snapshot")


@pytest.fixture(scope="module")
def cli_report(tmp_path_factory, full_run, periodic_run):
    out = tmp_path_factory.mktemp("report")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ANALYSIS_DIR), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.run([sys.executable, "-m", "tsg_analysis", "report", str(full_run[0]), str(periodic_run[0]),
                           "--out", str(out)], capture_output=True, text=True, env=env)  # density: params.json
    assert proc.returncode == 0, proc.stderr
    return out, json.loads((out / "summary.json").read_text(encoding="utf-8")), proc


def test_every_figure_and_table_is_written(cli_report):
    out, summary, proc = cli_report
    assert summary["not_produced"] == [], summary["not_produced"]
    for run in summary["runs"]:
        assert sorted(run["figures"]) == sorted(RUN_FIGURES)
        for name in run["figures"].values():
            assert (out / name).stat().st_size > 10_000, name
    assert sorted(summary["figures"]) == ["massflow_variants", "profiles", "rtd_comparison"]
    for name in ("report.md", "summary.json", "rtd_statistics.csv", "rtd_curves.csv", "profiles.csv",
                 "massflow.csv", "residence_means.csv", "differences.csv", "rtd_comparison.csv",
                 *summary["figures"].values()):
        assert (out / name).is_file(), name
    text = (out / "report.md").read_text(encoding="utf-8")
    assert "Everything was produced." in text and "![RTD](full_rtd.png)" in text
    assert "report.md" in proc.stdout


def test_numbers_in_the_json(cli_report, full_run):
    _, summary, _ = cli_report
    full, periodic = summary["runs"]
    assert full["steady_state"]["reached"] and full["steady_state"]["start_time_s"] == pytest.approx(STEADY_FROM)
    assert full["rtd"]["total"]["count"] == full_run[1].rtd_records
    assert full["rtd"]["total"]["mean"] == pytest.approx(MEAN_RESIDENCE, rel=0.05)
    assert sorted(full["rtd"]) == ["chopping", "conveying", "kneading", "total"]
    assert sorted(periodic["rtd"]) == ["conveying", "kneading", "total"]
    assert periodic["exit_reasons"]["pass"] > 0 and full["exit_reasons"]["outlet"] > 0
    assert full["element_profiles"]["labels"][:2] == ["C1", "K1"]
    assert full["element_profiles"]["solid_fraction"][1]["mean"] == pytest.approx(0.3)
    assert set(full["sensor_flow_kg_h"]) == {"sensor_1", "sensor_2", "sensor_3"}
    outlet = full["sensor_flow_kg_h"]["sensor_3"]
    # the fixture's outlet: 14.4 kg/h with white noise σ = 0.5 over 800 rows: 95 % half-width ≈ 1.96·0.5/√800
    assert abs(outlet["mean"] - 14.4) <= outlet["half_width"] and outlet["resolved"]
    assert outlet["half_width"] == pytest.approx(1.96 * 0.5 / 800**0.5, rel=0.25)
    assert full["parameters"]["rpm"] == 600 and full["steady_state"]["window_s"] == pytest.approx(0.1)
    total = full["mean_residence_time_s"]["from_records"]["total"]
    assert total["resolved"] and total["half_width"] < 0.05 * total["mean"]
    assert set(periodic["cross_sections"]) == {"conveying", "kneading"}
    assert all(c["agree"] for c in summary["comparisons"])  # same Gamma RTD, different seeds
    differences = {(d["quantity"], d["scope"]): d for d in summary["differences"]}
    inlet = differences[("mass flow", "sensor_1")]  # both fixtures feed 14.4 kg/h: no resolved difference
    assert not inlet["significant"] and inlet["text"].startswith("not resolved")
    kneading = differences[("solid fraction", "K1")]  # 0.3 in both, exactly: difference 0 ± 0
    assert kneading["value"] == pytest.approx(0.0, abs=1e-12) and not kneading["significant"]
    assert {c["scope"] for c in summary["comparisons"]} == {"total", "conveying", "kneading"}


def test_bad_inputs_are_reported_not_raised(tmp_path, periodic_run, unsteady_run):
    missing = tmp_path / "missing_files"
    shutil.copytree(periodic_run[0], missing)
    (missing / "massflow.txt").unlink()
    (missing / "elements.txt").unlink()
    truncated = tmp_path / "truncated"
    shutil.copytree(periodic_run[0], truncated)
    text = (truncated / "residence.txt").read_text(encoding="utf-8")
    (truncated / "residence.txt").write_text(text[:-25])  # killed mid-record
    (truncated / "zones.txt").write_text("1 conveying 0 0.01\n")  # damaged zones
    runs = [unsteady_run[0], missing, truncated, tmp_path / "nowhere"]
    report = build_report(runs, tmp_path / "out", settings=Settings(snapshot=False, require_steady=True))
    not_produced = {(run, part): reason for run, part, reason in report.not_produced}

    assert "never reached steady state" in report.runs[0].steady.message
    for part in ("RTD", "element profiles", "mean sensor flows"):
        assert "the run never reached steady state" in not_produced[("unsteady", part)]
    assert report.settings.require_steady
    assert ("unsteady", "cross-section maps") in not_produced  # no dumps in this fixture
    assert "massflow.txt: file not found" in not_produced[("missing_files", "steady state")]
    assert "no steady window" in not_produced[("missing_files", "RTD")]
    assert "zones.txt: line 1" in not_produced[("truncated", "zones")]
    assert any("last line is incomplete" in note for note in report.runs[2].notes)
    assert "not a directory" in not_produced[("nowhere", "everything")]

    text = (tmp_path / "out" / "report.md").read_text(encoding="utf-8")
    assert "## Not produced" in text and "never reached steady state" in text
    summary = json.loads((tmp_path / "out" / "summary.json").read_text(encoding="utf-8"))
    assert summary["runs"][0]["steady_state"]["reached"] is False
    assert len(summary["not_produced"]) == len(report.not_produced)


def test_an_unsteady_run_is_averaged_whole_and_flagged(tmp_path, unsteady_run):
    report = build_report([unsteady_run[0]], tmp_path, settings=Settings(snapshot=False))
    run = report.runs[0]
    assert run.transient and "total" in run.rtd_stats and run.profile is not None
    # the fixture's outlet sensor ramps up from 1.0 to 1.2 s: the ramp looks like a long correlation,
    # so the whole record holds too few independent samples for a number; stationary from ≈ 1.2 s
    outlet = run.sensor_flows["sensor_2"]
    assert 1.1 <= outlet.detected_start <= 1.3 and outlet.chosen_start < 1.01
    assert not outlet.resolved and outlet.text().startswith("window too short")
    assert run.sensor_flows["sensor_1"].resolved  # the inlet is stationary from the start
    text = (tmp_path / "report.md").read_text(encoding="utf-8")
    assert "Transient" in text and "window too short" in text


def test_a_450_rpm_run_is_analysed_at_450_rpm(tmp_path):
    """Issue 13: the steady window is one revolution of the run's own speed, read from params.json
    (60/450 s = 0.1333 s), never 600 rpm's 0.1 s; the TSG-PARAMETERS line is the fallback."""
    from make_fixture import write_run

    run_dir = tmp_path / "slow"
    write_run(run_dir, dumps=None, meshes=False, rpm=450.0, seed=4)
    report = build_report([run_dir], tmp_path / "out", settings=Settings(snapshot=False))
    run = report.runs[0]
    assert run.parameters.rpm == 450.0 and run.parameters.source.endswith("params.json")
    assert run.steady.window == pytest.approx(60.0 / 450.0)
    assert np.allclose(np.diff(run.steady.window_starts), 60.0 / 450.0)
    summary = json.loads((tmp_path / "out" / "summary.json").read_text(encoding="utf-8"))
    assert summary["runs"][0]["steady_state"]["window_s"] == pytest.approx(0.13333, rel=1e-4)
    assert "450 rpm" in (tmp_path / "out" / "report.md").read_text(encoding="utf-8")

    (run_dir / "params.json").unlink()  # the log's TSG-PARAMETERS line instead
    with open(run_dir / "log.lammps", "a", encoding="utf-8") as log:
        log.write("TSG-PARAMETERS rpm=450 screw_drive=corotating d_mean=0.0004 rho_p=1500 stats_every=2000\n")
    run = build_report([run_dir], tmp_path / "out2", settings=Settings(snapshot=False)).runs[0]
    assert run.parameters.rpm == 450.0 and run.parameters.rho_p == 1500.0 and "TSG-PARAMETERS" in run.parameters.source
    assert run.steady.window == pytest.approx(60.0 / 450.0)


def test_snapshot_draws_the_screws_in_the_pose_the_run_dumped(tmp_path, periodic_run):
    """The screws come from the run's screw dumps at the frame's step, not from rpm × t."""
    from tsg_analysis.dumps import find_dump_files, step_from_name
    from tsg_analysis.snapshot import screw_dumps_at

    run_dir = tmp_path / "posed"
    shutil.copytree(periodic_run[0], run_dir)
    last_step = step_from_name(find_dump_files(run_dir)[0][-1])
    for screw in ("screw1", "screw2"):
        (run_dir / "dumps" / f"screws_{screw}_{last_step}.vtk").write_bytes((run_dir / "meshes" / f"{screw}.stl").read_bytes())
        (run_dir / "dumps" / f"screws_{screw}_{last_step - 1000}.vtk").write_text("an earlier pose")
    assert [p.name for p in screw_dumps_at(run_dir, last_step)] == [f"screws_screw1_{last_step}.vtk",
                                                                    f"screws_screw2_{last_step}.vtk"]
    assert screw_dumps_at(tmp_path, last_step) == []


def test_periodicity_is_read_from_the_run_not_guessed(tmp_path, full_run):
    """VTK dumps carry no box: a periodic run (params.json case, or residence.txt's '# axis: periodic'
    header, as fix residence/time writes it) with no pass yet must not be counted as non-periodic."""
    run_dir = tmp_path / "periodic-vtk"
    shutil.copytree(full_run[0], run_dir)
    params = json.loads((run_dir / "params.json").read_text())
    (run_dir / "params.json").write_text(json.dumps({**params, "case": "periodic"}))
    run = build_report([run_dir], tmp_path / "a", settings=Settings(snapshot=False)).runs[0]
    assert run.plane_flows is None
    assert "periodic run with VTK dumps" in dict(run.missing)["mass flow through zone boundaries"]

    (run_dir / "params.json").unlink()
    text = (run_dir / "residence.txt").read_text()
    (run_dir / "residence.txt").write_text(text.replace("# tsg-dem residence records v1\n",
                                                        "# tsg-dem residence records v1\n# axis: periodic, passes\n"))
    (run_dir / "log.lammps").write_text((run_dir / "log.lammps").read_text() + "TSG-PARAMETERS rpm=600 rho_p=1263 "
                                        "d_mean=0.0004\n")
    run = build_report([run_dir], tmp_path / "b", settings=Settings(snapshot=False)).runs[0]
    assert "periodic run with VTK dumps" in dict(run.missing)["mass flow through zone boundaries"]
