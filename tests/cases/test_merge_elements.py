"""cases/slurm/merge-elements.sh: a segmented run's element statistics in one file, each sampled
step once. A continued segment starts from a restart file older than the step its predecessor
reached, so some steps are in two files; the later segment's rows must win (as the mass-flow and
residence records, whose fixes drop what the killed segment wrote after the restart file)."""
import os
import subprocess
from pathlib import Path

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
MERGE = ROOT / "cases" / "slurm" / "merge-elements.sh"
HEADER = "# Time-averaged data for fix element_stats\n# TimeStep Number-of-rows\n# Row c_elements[1] c_elements[2]\n"


def statistics(steps: range, value: float) -> str:
    """Two zones per block; every row of a file carries `value` so that the merge shows its source."""
    return HEADER + "".join(f"{step} 2\n1 {value} 0.5\n2 {value} 0.25\n" for step in steps)


def blocks(path: Path) -> list[tuple[int, float]]:
    out, step = [], None
    for line in path.read_text().splitlines():
        words = line.split()
        if line.startswith("#"):
            continue
        if len(words) == 2:
            step = int(words[0])
        elif words[0] == "1":
            out.append((step, float(words[1])))
    return out


def test_overlapping_segments_keep_the_later_rows_once(tmp_path):
    (tmp_path / "elements.upto-700.txt").write_text(statistics(range(100, 701, 100), 1.0))
    (tmp_path / "elements.upto-1300.txt").write_text(statistics(range(500, 1301, 100), 2.0))  # from restart.500
    (tmp_path / "elements.upto-1400.txt").write_text(HEADER)  # a segment killed before its first sample
    (tmp_path / "elements.txt").write_text(statistics(range(1200, 1601, 100), 3.0))           # from restart.1200
    subprocess.run([str(MERGE), str(tmp_path)], check=True)
    assert blocks(tmp_path / "elements.txt") == (
        [(s, 1.0) for s in range(100, 500, 100)] + [(s, 2.0) for s in range(500, 1200, 100)]
        + [(s, 3.0) for s in range(1200, 1601, 100)])
    assert (tmp_path / "elements.txt").read_text().startswith(HEADER)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["elements.txt"]


def test_a_run_in_one_piece_is_left_as_it_is(tmp_path):
    text = statistics(range(100, 501, 100), 1.0)
    (tmp_path / "elements.txt").write_text(text)
    subprocess.run([str(MERGE), str(tmp_path)], check=True)
    assert (tmp_path / "elements.txt").read_text() == text


def test_the_analysis_reads_a_going_run_as_the_merge_writes_it_and_changes_nothing(tmp_path):
    """A chain that is still going: its segments are read as they are (the running segment's
    elements.txt with a cut last line), equal to what the merge writes once it has stopped, and no
    file is replaced (a running lmp would go on writing to a file no longer in the folder)."""
    from tsg_analysis.run_files import read_element_statistics

    def full(steps: range, value: float) -> str:   # the five columns of the element statistics
        return (HEADER.replace("c_elements[2]", "c_elements[2] c_elements[3] c_elements[4] c_elements[5]")
                + "".join(f"{step} 2\n1 {value} 0.5 0.1 3 0.001\n2 {value} 0.25 0.1 3 0.001\n" for step in steps))

    (tmp_path / "elements.upto-700.txt").write_text(full(range(100, 701, 100), 1.0))
    (tmp_path / "elements.upto-1300.txt").write_text(full(range(500, 1301, 100), 2.0))
    (tmp_path / "elements.txt").write_text(full(range(1200, 1601, 100), 3.0) + "1700 2\n1 3.0")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    going = read_element_statistics(tmp_path)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    assert any("last line is incomplete" in issue for issue in going.issues), going.issues
    subprocess.run([str(MERGE), str(tmp_path)], check=True)
    merged = read_element_statistics(tmp_path / "elements.txt")
    assert list(going.timesteps) == list(merged.timesteps) == list(range(100, 1601, 100))
    assert [row[0][0] for row in going.values] == [v for _, v in blocks(tmp_path / "elements.txt")]

    # a new segment killed before it wrote elements.txt: the earlier segments are the record
    (tmp_path / "elements.txt").rename(tmp_path / "elements.upto-1700.txt")
    assert list(read_element_statistics(tmp_path).timesteps) == list(range(100, 1601, 100))
