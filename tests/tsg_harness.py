"""Run our `lmp` on an input in a scratch directory and read back what it did.

Used by every LIGGGHTS-level test:

    run = run_lmp(text, tmp_path, nprocs=2, variables={"seed": 15485863})
    run.assert_clean()                  # no warning that matters
    ke = run.thermo[-1]["KinEng"]       # numpy arrays, one dict per `run` command

Environment (set by ctest, see tests/CMakeLists.txt): TSG_LMP (the executable), TSG_MPIEXEC; lmp
is started by the project's one launcher, tsg_cases.launcher.
"""
from __future__ import annotations

import re
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Mapping

import numpy as np

from tsg_analysis.liggghts_log import parse_thermo, parse_warnings
from tsg_cases.launcher import errors as lmp_errors
from tsg_cases.launcher import lmp_command, lmp_environment, lmp_executable, mpi_command

__all__ = ["LmpFailed", "LmpRun", "lmp_executable", "mpi_command", "run_lmp"]

# Warnings that make a run untrustworthy. Tests may allow others explicitly.
WARNINGS_THAT_MATTER = (
    re.compile(r"not located in any whitelist"),          # contact-model slow path
    re.compile(r"[Ll]ost atoms"),
    re.compile(r"[Mm]esh"),                                # any mesh-quality / mesh-geometry warning
    re.compile(r"angle", re.IGNORECASE),
    re.compile(r"neighbo", re.IGNORECASE),
    re.compile(r"time ?step", re.IGNORECASE),
    re.compile(r"overlap", re.IGNORECASE),
)

class LmpFailed(AssertionError):
    """lmp exited with an error, or a run contains a warning that matters."""


@dataclass
class LmpRun:
    workdir: Path
    returncode: int
    stdout: str
    stderr: str
    log: str
    thermo: list[dict[str, np.ndarray]] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)

    def warnings_that_matter(self, allow: Iterable[str] = ()) -> list[str]:
        allowed = [re.compile(a) for a in allow]
        return [w for w in self.warnings
                if any(p.search(w) for p in WARNINGS_THAT_MATTER)
                and not any(a.search(w) for a in allowed)]

    def assert_clean(self, allow: Iterable[str] = ()) -> None:
        bad = self.warnings_that_matter(allow)
        if bad:
            raise LmpFailed(f"lmp run in {self.workdir} emitted warnings that matter:\n  " + "\n  ".join(bad))

    def last(self, column: str) -> float:
        return float(self.thermo[-1][column][-1])


def run_lmp(input_text: str, workdir: Path | str, nprocs: int = 1,
            variables: Mapping[str, object] | None = None,
            files: Mapping[str, str | bytes | Path] | None = None,
            timeout: float = 600, expect_error: bool = False,
            input_name: str = "in.test") -> LmpRun:
    """Run lmp on `input_text` in `workdir`.

    files: extra files to place in workdir (name -> text, bytes, or a Path to copy).
    Raises LmpFailed when lmp fails (unless expect_error) or when expect_error and it succeeds.
    """
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    for name, content in (files or {}).items():
        target = workdir / name
        target.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, Path):
            shutil.copyfile(content, target)
        elif isinstance(content, bytes):
            target.write_bytes(content)
        else:
            target.write_text(content)
    (workdir / input_name).write_text(input_text)

    cmd = lmp_command(input_name, variables, nprocs)
    proc = subprocess.run(cmd, cwd=workdir, capture_output=True, timeout=timeout, env=lmp_environment(),
                          encoding="utf-8", errors="replace")  # LIGGGHTS may print stray bytes
    log_path = workdir / "log.lammps"
    log = log_path.read_text(errors="replace") if log_path.exists() else ""
    run = LmpRun(workdir=workdir, returncode=proc.returncode, stdout=proc.stdout, stderr=proc.stderr,
                 log=log, thermo=parse_thermo(log), warnings=parse_warnings(log),
                 errors=lmp_errors(log, proc.stdout, proc.stderr))
    if expect_error:
        if proc.returncode == 0:
            raise LmpFailed(f"lmp was expected to fail but succeeded in {workdir}")
    elif proc.returncode != 0:
        tail = "\n".join((log or proc.stdout).splitlines()[-25:])
        raise LmpFailed(f"lmp failed (exit {proc.returncode}) in {workdir}:\n{tail}\nstderr:\n{proc.stderr[-3000:]}")
    return run
