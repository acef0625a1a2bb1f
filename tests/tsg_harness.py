"""Run our `lmp` on an input in a scratch directory and read back what it did: the test suite's
name for the project's one launcher, tsg_cases.launcher (installed by the set-up).

Used by every LIGGGHTS-level test:

    run = run_lmp(text, tmp_path, nprocs=2, variables={"seed": 15485863})
    run.assert_clean()                  # no warning that matters
    ke = run.thermo[-1]["KinEng"]       # numpy arrays, one dict per `run` command

Environment (set by ctest, see tests/CMakeLists.txt): TSG_LMP (the executable), TSG_MPIEXEC.
"""
from __future__ import annotations

from tsg_cases.launcher import WARNINGS_THAT_MATTER, LmpFailed, LmpRun, lmp_executable, mpi_command, run_lmp

__all__ = ["WARNINGS_THAT_MATTER", "LmpFailed", "LmpRun", "lmp_executable", "mpi_command", "run_lmp"]
