"""The one way this project starts `lmp`: executable, MPI prefix, environment, first error.

Used by the case runner, the test harness (tests/tsg_harness.py), the benchmarks and the scripts.

    command = lmp_command("in.case", {"rpm": 600}, nprocs=2)
    proc = subprocess.run(command, cwd=run_dir, env=lmp_environment())
    message = first_error(run_dir)          # the error LIGGGHTS reported, from the log or screen

    run = run_lmp(text, workdir, nprocs=2, variables={"seed": 15485863})   # an input text, parsed back
    run.assert_clean()                      # no warning that matters
    ke = run.thermo[-1]["KinEng"]           # numpy arrays, one dict per `run` command

Environment: TSG_LMP (the executable; default <repository>/build/lmp), TSG_MPIEXEC (mpirun).
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Mapping

import numpy as np

from tsg_analysis.liggghts_log import parse_errors, parse_thermo, parse_warnings

ROOT = Path(__file__).resolve().parents[1]


class LauncherError(RuntimeError):
    """lmp or mpirun cannot be started: the message names what is missing and how to fix it."""


def lmp_executable() -> str:
    """TSG_LMP, or the build's lmp; checked to exist and be executable."""
    configured = os.environ.get("TSG_LMP")
    path = Path(configured) if configured else ROOT / "build" / "lmp"
    where = f"TSG_LMP={configured}" if configured else f"{path} (set TSG_LMP or build the project: ./tsg setup)"
    if not path.is_file():
        raise LauncherError(f"lmp executable not found: {where}")
    if not os.access(path, os.X_OK):
        raise LauncherError(f"lmp executable is not executable: {where}")
    return str(path)


def mpi_command(nprocs: int) -> list[str]:
    """mpirun prefix for nprocs ranks (running as root and oversubscription allowed)."""
    if nprocs < 1:
        raise LauncherError(f"number of MPI ranks {nprocs} is not allowed: use 1 or more")
    launcher = os.environ.get("TSG_MPIEXEC") or shutil.which("mpirun") or shutil.which("mpiexec")
    if not launcher or not shutil.which(launcher):
        raise LauncherError(f"mpirun not found (TSG_MPIEXEC={os.environ.get('TSG_MPIEXEC', '')}): "
                            "install openmpi-bin or run with 1 rank")
    return [launcher, "-np", str(nprocs), "--oversubscribe", "--allow-run-as-root", "--bind-to", "none"]


def lmp_command(input_file: str | Path, variables: Mapping[str, object] | None = None, nprocs: int = 1,
                log: str = "log.lammps") -> list[str]:
    """The full command line: [mpirun ...] lmp -in INPUT -log LOG -echo none -var NAME VALUE ..."""
    command = [lmp_executable(), "-in", str(input_file), "-log", log, "-echo", "none"]
    for name, value in (variables or {}).items():
        command += ["-var", str(name), str(value)]
    return (mpi_command(nprocs) + command) if nprocs > 1 else command


def lmp_environment(extra: Mapping[str, str] | None = None) -> dict[str, str]:
    """os.environ plus what OpenMPI needs to run as root in containers."""
    return dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", **(extra or {}))


def errors(*texts: str) -> list[str]:
    """Every ERROR line LIGGGHTS printed in these texts (log, screen, stderr), in order."""
    return parse_errors("\n".join(texts))


def first_error(run_dir: Path, log: str = "log.lammps", screen: str = "screen.txt") -> str | None:
    """The first error of a failed run: from the log, else from the captured screen output."""
    texts = [(run_dir / name).read_text(errors="replace") for name in (log, screen) if (run_dir / name).is_file()]
    found = errors(*texts)
    return found[0] if found else None


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
                 errors=errors(log, proc.stdout, proc.stderr))
    if expect_error:
        if proc.returncode == 0:
            raise LmpFailed(f"lmp was expected to fail but succeeded in {workdir}")
    elif proc.returncode != 0:
        tail = "\n".join((log or proc.stdout).splitlines()[-25:])
        raise LmpFailed(f"lmp failed (exit {proc.returncode}) in {workdir}:\n{tail}\nstderr:\n{proc.stderr[-3000:]}")
    return run
