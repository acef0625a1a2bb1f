"""The CLI writes every figure, the JSON and the CSVs for a fixture; bad input gives a report that
says what could not be produced instead of a crash."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

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
                           "--out", str(out), "--density", "1263"], capture_output=True, text=True, env=env)
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
                 "massflow.csv", "rtd_comparison.csv", *summary["figures"].values()):
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
    assert full["element_profiles"]["solid_fraction"][1] == pytest.approx(0.3)
    assert set(full["sensor_mean_kg_h"]) == {"sensor_1", "sensor_2", "sensor_3"}
    assert full["sensor_mean_kg_h"]["sensor_3"] == pytest.approx(14.4, rel=0.02)
    assert set(periodic["cross_sections"]) == {"conveying", "kneading"}
    assert all(c["agree"] for c in summary["comparisons"])  # same Gamma RTD, different seeds
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
    report = build_report(runs, tmp_path / "out", settings=Settings(snapshot=False))
    not_produced = {(run, part): reason for run, part, reason in report.not_produced}

    assert "never reached steady state" in report.runs[0].steady.message
    for part in ("RTD", "element profiles", "mean sensor flows"):
        assert "the run never reached steady state" in not_produced[("unsteady", part)]
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


def test_allow_transient_averages_anyway(tmp_path, unsteady_run):
    report = build_report([unsteady_run[0]], tmp_path, settings=Settings(snapshot=False, allow_transient=True))
    run = report.runs[0]
    assert run.transient and "total" in run.rtd_stats and run.profile is not None
    assert "Transient" in (tmp_path / "report.md").read_text(encoding="utf-8")
