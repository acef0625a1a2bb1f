"""machine.in, the one source of the machine geometry, against the meshes it is written with."""
from __future__ import annotations

import numpy as np

from tsg_meshes.build import write_geometry
from tsg_meshes.machine import MACHINE_FILE, read_machine
from tsg_meshes.surface import read_ascii_stl


def test_machine_file_matches_the_written_meshes(build, tmp_path):
    write_geometry(build("consigma1-periodic"), tmp_path)
    machine = read_machine(tmp_path / MACHINE_FILE)
    assert machine["axis2_y"] - machine["axis1_y"] == machine["centre_distance"]
    assert machine["axis1_y"] == -machine["axis2_y"]
    barrel = read_ascii_stl(tmp_path / "barrel.stl").reshape(-1, 3)
    # the bore's outermost vertices reach |y| = a/2 + R and |z| = R within the chordal tolerance
    tolerance = build("consigma1-periodic").tolerance
    np.testing.assert_allclose(np.abs(barrel[:, 1]).max(), machine["axis2_y"] + machine["bore_radius"], atol=tolerance)
    np.testing.assert_allclose(np.abs(barrel[:, 2]).max(), machine["bore_radius"], atol=tolerance)
    # every barrel vertex is on one of the two bore circles (within the chordal tolerance)
    left = np.hypot(barrel[:, 1] - machine["axis1_y"], barrel[:, 2] - machine["axis_z"])
    right = np.hypot(barrel[:, 1] - machine["axis2_y"], barrel[:, 2] - machine["axis_z"])
    on_bore = np.minimum(np.abs(left - machine["bore_radius"]), np.abs(right - machine["bore_radius"]))
    assert on_bore.max() < 1e-6
    # the simulation box of domain.in contains the barrel
    assert np.abs(barrel[:, 1]).max() < machine["box_y"] and np.abs(barrel[:, 2]).max() < machine["box_z"]
    screw = read_ascii_stl(tmp_path / "screw1.stl").reshape(-1, 3)
    radius = np.hypot(screw[:, 1] - machine["axis1_y"], screw[:, 2] - machine["axis_z"])
    np.testing.assert_allclose(radius.max(), machine["screw_outer_radius"], atol=tolerance)
