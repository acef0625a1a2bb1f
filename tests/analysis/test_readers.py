"""Readers round-trip files in the team's formats, keep what a killed run left, and name bad lines."""
import numpy as np
import pytest

from tsg_analysis.dumps import find_dump_files, iter_frames, read_text_dump, read_vtk_dump, step_from_name
from tsg_analysis.run_files import (AnalysisInputError, read_element_statistics, read_massflow, read_residence,
                                    read_zones)

RESIDENCE = """# tsg-dem residence records v1
# written by fix residence (test)
# columns: id entry_time exit_time residence_time exit_reason time_conveying time_kneading time_chopping time_zone_1 time_zone_2
7 0.1 0.5 0.4 outlet 0.3 0.1 0 0.3 0.1
8 0.2 0.9 0.7 pass 0.5 0.2 0 0.5 0.2
9 0.3 1.0 0.7 inside 0.6 0.1 0 0.6 0.1
10 0.4 0.6 0.2 deleted 0.2 0 0 0.2 0
11 0.5 0.7 0.2 lost 0.1 0.1 0 0.1 0.1
"""
ELEMENTS = """# Time-averaged data for fix elements
# TimeStep Number-of-rows
# Row c_zones[1] c_zones[2] c_zones[3] c_zones[4] c_zones[5]
1000 2
1 0.1 0.5 0.25 10 1e-5
2 0.3 0.8 0.05 30 3e-5
2000 2
1 0.2 0.6 0.35 20 2e-5
2 0.4 0.9 0.15 40 4e-5
"""
MASSFLOW = """# tsg-dem mass flow v1
# columns: step time sensor_1 sensor_2
100 0.001 14.0 -1.5
200 0.002 15.0 13.5
"""
ZONES = """# index type x_start x_end free_volume
1 conveying 0.0 0.025 1.0e-5
2 kneading 0.025 0.03125 2.7e-6
3 chopping 0.03125 0.0354 1.8e-6
"""


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_zones_round_trip(tmp_path):
    zones = read_zones(write(tmp_path, "zones.txt", ZONES))
    assert zones.kind == ("conveying", "kneading", "chopping")
    assert zones.labels == ["C1", "K1", "CH1"]
    np.testing.assert_allclose(zones.x_end, [0.025, 0.03125, 0.0354])
    assert zones.ranges("kneading") == [(0.025, 0.03125)]


def test_residence_round_trip(tmp_path):
    records = read_residence(write(tmp_path, "residence.txt", RESIDENCE))
    assert list(records.ids) == [7, 8, 9, 10, 11]
    assert list(records.exit_reason) == ["outlet", "pass", "inside", "deleted", "lost"]
    np.testing.assert_allclose(records.residence_time, [0.4, 0.7, 0.7, 0.2, 0.2])
    np.testing.assert_allclose(records.time_by_type["kneading"], [0.1, 0.2, 0.1, 0, 0.1])
    np.testing.assert_allclose(records.time_by_zone[:, 1], [0.1, 0.2, 0.1, 0, 0.1])
    assert records.reason_counts() == {"outlet": 1, "pass": 1, "deleted": 1, "lost": 1, "inside": 1}
    assert records.issues == ()


def test_residence_truncated_last_line_is_dropped_and_said(tmp_path):
    records = read_residence(write(tmp_path, "residence.txt", RESIDENCE + "12 0.6 0.9 0.3 out"))
    assert len(records) == 5
    assert "incomplete" in records.issues[0]


def test_fixture_residence_is_consistent(periodic_run):
    run_dir, truth = periodic_run
    records = read_residence(run_dir / "residence.txt")
    assert len(records) == truth.records
    np.testing.assert_allclose(records.time_by_zone.sum(axis=1), records.residence_time, rtol=1e-6)
    np.testing.assert_allclose(records.time_by_type["conveying"] + records.time_by_type["kneading"],
                               records.residence_time, rtol=1e-6)


@pytest.mark.parametrize("text, message", [
    (RESIDENCE.replace("8 0.2 0.9 0.7 pass", "8 0.2 0.9 0.7 escaped"), "line 5 is not numeric"),
    (RESIDENCE.replace("8 0.2 0.9 0.7 pass 0.5", "8 0.2 0.9 0.7 pass"), "line 5 has 9 fields, expected 10"),
    (RESIDENCE.replace("# tsg-dem residence records v1\n", ""), "missing the '# tsg-dem residence records v1'"),
    (RESIDENCE.replace("time_zone_2", "time_zone_3"), "columns must be"),
])
def test_residence_damage_is_named(tmp_path, text, message):
    with pytest.raises(AnalysisInputError, match=message):
        read_residence(write(tmp_path, "residence.txt", text))


def test_missing_file_is_named(tmp_path):
    with pytest.raises(AnalysisInputError, match="residence.txt: file not found"):
        read_residence(tmp_path / "residence.txt")


def test_element_statistics_round_trip(tmp_path):
    stats = read_element_statistics(write(tmp_path, "elements.txt", ELEMENTS))
    assert list(stats.timesteps) == [1000, 2000]
    np.testing.assert_allclose(stats.column("solid_fraction"), [[0.1, 0.3], [0.2, 0.4]])
    np.testing.assert_allclose(stats.column("count"), [[10, 30], [20, 40]])


def test_element_statistics_truncated_block_is_dropped(tmp_path):
    stats = read_element_statistics(write(tmp_path, "elements.txt", ELEMENTS + "3000 2\n1 0.5 0.5 0.5 5 1e-5\n2 0.4"))
    assert list(stats.timesteps) == [1000, 2000]
    assert any("incomplete" in issue for issue in stats.issues)


def test_element_statistics_bad_row_is_named(tmp_path):
    with pytest.raises(AnalysisInputError, match="line 9: expected row 2"):
        read_element_statistics(write(tmp_path, "elements.txt", ELEMENTS.replace("2 0.4 0.9", "3 0.4 0.9")))


def test_massflow_round_trip_and_truncation(tmp_path):
    record = read_massflow(write(tmp_path, "massflow.txt", MASSFLOW + "300 0.003 1"))
    assert record.sensor_names == ("sensor_1", "sensor_2")
    np.testing.assert_allclose(record.flow, [[14.0, -1.5], [15.0, 13.5]])
    assert list(record.step) == [100, 200]
    assert record.issues


def test_text_dump_round_trip_with_truncated_last_frame(tmp_path):
    frame = ("ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp ff ff\n0 0.1\n-0.02 0.02\n"
             "-0.0125 0.0125\nITEM: ATOMS id type x y z vx vy vz radius\n"
             "1 1 0.01 0.002 0.003 0.2 0 0 0.0002\n2 1 0.02 -0.002 0.001 -0.1 0 0 0.0003\n")
    text = frame.format(step=100) + frame.format(step=200)
    path = write(tmp_path, "particles_100.txt", text + frame.format(step=300)[:-30])
    frames, issues = read_text_dump(path)
    assert [f.step for f in frames] == [100, 200]
    assert "last frame is incomplete" in issues[0]
    first = frames[0]
    assert list(first.columns["id"]) == [1, 2] and first.columns["id"].dtype == np.int64
    np.testing.assert_allclose(first.columns["vx"], [0.2, -0.1])
    assert first.box.periodic == (True, False, False)
    np.testing.assert_allclose(first.volume, 4 / 3 * np.pi * np.array([2e-4, 3e-4]) ** 3)


def test_text_dump_damaged_frame_before_the_end_is_an_error(tmp_path):
    frame = ("ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
             "ITEM: ATOMS id x y z\n1 0.1 0.2 0.3\n")
    with pytest.raises(AnalysisInputError, match="frame 1 is incomplete"):
        read_text_dump(write(tmp_path, "particles_0.txt", frame.format(step=0) + frame.format(step=1)))


def test_fixture_dumps_round_trip(periodic_run, full_run):
    for run_dir, truth in (periodic_run, full_run):
        paths, notes = find_dump_files(run_dir)
        assert len(paths) == 5 and not notes
        frames = list(iter_frames(paths))
        assert [f.step for f in frames] == sorted(step_from_name(p) for p in paths)
        for name in ("id", "type", "x", "y", "z", "vx", "vy", "vz", "radius"):
            assert name in frames[0].columns
        assert frames[0].columns["x"].max() <= truth.zone_edges[-1]


def test_vtk_dump_matches_its_content(full_run):
    run_dir, _ = full_run
    path = sorted((run_dir / "dumps").glob("*.vtk"), key=step_from_name)[0]
    frame = read_vtk_dump(path)
    assert frame.step == step_from_name(path) and frame.box is None
    assert frame.columns["id"].dtype == np.int64
    assert len(np.unique(frame.columns["id"])) == len(frame)
    assert np.all((frame.columns["radius"] > 1.7e-4) & (frame.columns["radius"] < 2.3e-4))


def test_damaged_vtk_dump_is_an_input_error(tmp_path):
    path = write(tmp_path, "particles_5.vtk", "# vtk DataFile Version 2.0\ncut here")
    with pytest.raises(AnalysisInputError, match="particles_5.vtk"):
        read_vtk_dump(path)


def test_bounding_box_files_of_vtk_dumps_are_not_frames(tmp_path):
    """dump custom/vtk writes particles_boundingBox_<step>.vtk beside particles_<step>.vtk (seen in a real run)."""
    dumps = tmp_path / "dumps"
    dumps.mkdir()
    for name in ("particles_2000.vtk", "particles_boundingBox_2000.vtk", "particles_4000.vtk",
                 "particles_boundingBox_4000.vtk"):
        (dumps / name).write_text("# vtk DataFile Version 2.0\n")
    paths, _ = find_dump_files(tmp_path)
    assert [p.name for p in paths] == ["particles_2000.vtk", "particles_4000.vtk"]


def test_residence_analysis_domain_from_the_header(tmp_path):
    path = tmp_path / "residence.txt"
    path.write_text(RESIDENCE.replace("# written by fix residence (test)\n", "# analysis domain: [0.005, 0.0908)\n"))
    assert read_residence(path).analysis_domain == (0.005, 0.0908)
    path.write_text(RESIDENCE)
    assert read_residence(path).analysis_domain is None   # no line: the whole axis
    path.write_text(RESIDENCE.replace("# written by fix residence (test)\n", "# analysis domain: 0.005 to 0.09\n"))
    with pytest.raises(AnalysisInputError, match="analysis domain '0.005 to 0.09'"):
        read_residence(path)
