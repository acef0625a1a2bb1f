"""The README's time figures are the measured ones: the main job's and the test suite's minutes are
the measurements in docs/measured/*.json (written by scripts/measure-figures.py, sections `main-job`
and `tests`) rounded to the minute, and each sentence links to docs/measured.md. A figure typed by
hand, or left behind after a new measurement, fails here."""
from __future__ import annotations

import json
import os
import re
import statistics
from pathlib import Path

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
README = (ROOT / "README.md").read_text(encoding="utf-8")
MEASURED = ROOT / "docs" / "measured"


def minutes(seconds: float) -> int:
    return int(seconds / 60.0 + 0.5)


def sentence(pattern: str) -> re.Match[str]:
    found = re.search(pattern, README, re.DOTALL)
    assert found, f"README.md has no sentence matching {pattern!r}"
    return found


def test_main_job_minutes_are_measured() -> None:
    data = json.loads((MEASURED / "main_job.json").read_text())
    wall = statistics.median(run["wall_s"] for run in data["runs"])
    found = sentence(r"About (\d+) min on 2 idle cores after set-up\s*\(\[measured\]\(docs/measured\.md#([\w-]+)\)")
    assert int(found.group(1)) == minutes(wall), (
        f"README says {found.group(1)} min for the main job; docs/measured/main_job.json: {wall:.0f} s")
    assert found.group(2).startswith("main-job")


def test_test_suite_minutes_are_measured() -> None:
    data = json.loads((MEASURED / "test_suite.json").read_text())
    assert data["failed"] == 0 and data["tests"] > 0
    found = sentence(r"About (\d+) min of tests,\s+(\d+) min with the set-up,.*?"
                     r"\(\[measured\]\(docs/measured\.md#([\w-]+)\)")
    assert int(found.group(1)) == minutes(data["ctest_s"]), (
        f"README says {found.group(1)} min of tests; docs/measured/test_suite.json: {data['ctest_s']:.0f} s")
    assert int(found.group(2)) == minutes(data["wall_s"]), (
        f"README says {found.group(2)} min with the set-up; docs/measured/test_suite.json: {data['wall_s']:.0f} s")
    assert found.group(3).startswith("test-suite")


def test_minutes_round_to_the_nearest() -> None:
    assert [minutes(s) for s in (29.9, 30.0, 89.9, 90.0, 599.0)] == [0, 1, 1, 2, 10]
