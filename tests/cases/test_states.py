"""A kept state from any restart file of a run (cases/states.py, `keep --restart`): e.g. the faithful
400 um run's, in its sampling window, which the paper-scale time-step ladder starts from. The state
ends where the restart file was written: its step from the file's name, its time from the thermo row
at that step (the run's logs, a kept run's segments included)."""
import json
import lzma

import pytest
from tsg_cases import states

LOG = """Step Time Atoms KinEng
{rows}
Loop time of 1.0 on 1 procs for 100 steps with 10 atoms
"""


def run_dir(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    (run / "params.json").write_text(json.dumps({
        "case": "periodic", "scale": "paper", "seed": 12345, "np": 1, "git_commit": "abc",
        "variables": {"t_startup": "0.5", "t_sample": "1.0", "dt_fraction": "0.1", "out_dir": "/somewhere"}}))
    (run / "fill.vars").write_text("variable d_min equal 0.0003\nvariable fill_count equal 10\n")
    # an earlier segment's log and the current one (a kept run continued from restart.200)
    (run / "log.upto-200.lammps").write_text(LOG.format(rows="100 0.25 10 1.0\n200 0.5125 10 1.0"))
    (run / "log.lammps").write_text(LOG.format(rows="200 0.5125 10 1.0\n300 0.75 10 1.0"))
    for step in (200, 250):
        (run / f"restart.{step}").write_bytes(f"restart at {step}".encode())
    return run


def test_a_state_from_a_restart_file_ends_at_that_files_step_and_time(tmp_path):
    run = run_dir(tmp_path)
    state = states.keep(run, tmp_path / "state" / "seed-12345", run / "restart.200")
    assert (state.step, state.time, state.t_startup) == (200, 0.5125, 0.5125)
    assert (state.case, state.scale, state.seed) == ("periodic", "paper", 12345)
    assert lzma.decompress(state.restart.read_bytes()) == b"restart at 200"
    assert "--restart RUN/restart.200" in state.command and "out_dir" not in state.command
    assert states.read(state.path) == state


def test_a_state_of_a_chain_prepared_run_names_the_chains_own_options(tmp_path):
    # a kept run (scripts/kept-run.sh) is prepared once with options params.json does not keep
    run = run_dir(tmp_path)
    (run / "prepared-with").write_text("--scale paper --holdup-g 2.7 -v t_startup 0.1\n")
    state = states.keep(run, tmp_path / "state" / "seed-12345", run / "restart.200")
    assert state.command.startswith("tsg-run-case periodic --scale paper --holdup-g 2.7 -v t_startup 0.1 --out RUN "
                                    "(continued past step 200)")


def test_a_restart_file_off_the_thermo_rows_or_misnamed_is_refused(tmp_path):
    run = run_dir(tmp_path)
    with pytest.raises(states.StateError, match="no thermo row at step 250"):
        states.keep(run, tmp_path / "state", run / "restart.250")
    (run / "restart.bin").write_bytes(b"x")
    with pytest.raises(states.StateError, match="not a restart file restart.STEP"):
        states.keep(run, tmp_path / "state", run / "restart.bin")
