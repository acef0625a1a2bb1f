"""`mpirun -np 2 lmp` reproduces the serial run of a deterministic input at printed precision."""
from pathlib import Path

import numpy as np

from tsg_harness import run_lmp

INPUTS = Path(__file__).parent / "inputs"


def test_two_ranks_reproduce_serial_thermo(tmp_path):
    text = (INPUTS / "in.settle_bed").read_text()
    # short: granular flow is chaotic, round-off must not have grown to the printed digits
    serial = run_lmp(text, tmp_path / "np1", variables={"nsteps": 3000})
    parallel = run_lmp(text, tmp_path / "np2", nprocs=2, variables={"nsteps": 3000})
    serial.assert_clean()
    parallel.assert_clean()
    assert "2 by 1 by 1" in parallel.log or "1 by 2 by 1" in parallel.log or "1 by 1 by 2" in parallel.log
    s, p = serial.thermo[-1], parallel.thermo[-1]
    assert list(s) == list(p)
    assert len(s["Step"]) == 7
    for column in s:
        np.testing.assert_array_equal(s[column], p[column], err_msg=f"thermo column {column}")
