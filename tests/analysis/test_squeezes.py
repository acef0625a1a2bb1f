"""squeezes.txt (fix squeeze/ledger) is read as written, and the ledger of a window counts, rates
and places its events as a hand count of the same records does."""
import numpy as np
import pytest

from tsg_analysis.run import Run
from tsg_analysis.run_files import AnalysisInputError, read_squeezes

ZONES = """# tsg-dem zones v1
# index type x_start x_end free_volume
1 conveying 0.0 0.01 1e-6
2 kneading 0.01 0.02 1e-6
"""
HEADER = """# tsg-dem squeeze records v1
# fix squeeze squeeze/ledger, group all, walls fix walls
# walls (bit k of the mask): 0=screw1 1=screw2 2=barrel
# columns: start_time end_time id x y z radius peak_wall_ratio peak_pair_ratio walls kind with_particles \
start_speed release_speed event_number
"""  # the backslash joins the columns line


def squeeze_file(rows: list[tuple]) -> str:
    return HEADER + "".join(" ".join(str(v) for v in row) + "\n" for row in rows)


# (start, end, id, x, peak wall, peak pair, kind, release speed, number)
EVENTS = [(0.10, 0.11, 7, 0.005, 0.30, 0.00, 0, 9.0, 1), (0.20, 0.21, 7, 0.015, 0.50, 0.10, 1, 3.0, 2),
          (0.30, 0.32, 8, 0.012, 0.20, 0.00, 0, 6.0, 1), (0.50, 0.55, 9, 0.018, 0.00, 0.40, 3, 1.0, 1)]


def rows() -> list[tuple]:
    return [(s, e, i, x, 0, 0, 2e-4, w, p, 3, k, int(p > 0), 0.5, v, n) for s, e, i, x, w, p, k, v, n in EVENTS]


def test_the_records_are_read_as_written(tmp_path):
    (tmp_path / "squeezes.txt").write_text(squeeze_file(rows()))
    records = read_squeezes(tmp_path / "squeezes.txt")
    assert len(records) == 4 and records.wall_names == ("screw1", "screw2", "barrel")
    np.testing.assert_array_equal(records["release_speed"], [9.0, 3.0, 6.0, 1.0])
    np.testing.assert_array_equal(records["kind"], [0, 1, 0, 3])


def test_the_ledger_of_a_window_matches_a_hand_count(tmp_path):
    (tmp_path / "squeezes.txt").write_text(squeeze_file(rows()))
    (tmp_path / "zones.txt").write_text(ZONES)
    ledger = Run(tmp_path).squeeze_ledger(0.0, 0.4)     # the first three events end inside
    assert ledger.events == 3 and ledger.distinct_particles == 2
    assert ledger.events_per_particle == pytest.approx(1.5)
    assert ledger.rate.mean == pytest.approx(3 / 0.4)   # events per second: the bins' mean is the total rate
    assert ledger.release_speed.mean == pytest.approx(6.0)
    assert ledger.peak_wall_quantiles[1.0] == 0.5 and ledger.peak_wall_quantiles[0.5] == pytest.approx(0.3)
    assert ledger.by_kind == {"two_walls": 2, "wall_and_particles": 1, "wall_alone": 0, "particles": 0}
    assert ledger.by_zone == {"C1": 1, "K1": 2}
    assert "3 events, 2 particles" in ledger.text()


def test_a_bad_kind_and_a_wrong_header_are_refused(tmp_path):
    bad = rows()
    bad[0] = bad[0][:10] + (7,) + bad[0][11:]
    (tmp_path / "squeezes.txt").write_text(squeeze_file(bad))
    with pytest.raises(AnalysisInputError, match="kind must be 0 .. 3"):
        read_squeezes(tmp_path / "squeezes.txt")
    (tmp_path / "squeezes.txt").write_text(squeeze_file(rows()).replace("event_number", "n"))
    with pytest.raises(AnalysisInputError, match="columns must be"):
        read_squeezes(tmp_path / "squeezes.txt")


def test_an_empty_ledger_says_so(tmp_path):
    (tmp_path / "squeezes.txt").write_text(HEADER)
    (tmp_path / "zones.txt").write_text(ZONES)
    with pytest.raises(AnalysisInputError, match="no squeeze events"):
        Run(tmp_path).squeeze_ledger()


def test_the_report_shows_the_ledger_and_its_figure(tmp_path):
    from tsg_analysis.report import build_report
    run = tmp_path / "run"
    run.mkdir()
    (run / "squeezes.txt").write_text(squeeze_file(rows()))
    (run / "zones.txt").write_text(ZONES)
    build_report([run], tmp_path / "report")
    text = (tmp_path / "report" / "report.md").read_text()
    assert "### Squeezes" in text and "4 events, 3 particles" in text
    assert (tmp_path / "report" / "run_squeezes.png").stat().st_size > 0
