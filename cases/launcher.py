"""The one way this project starts `lmp`: executable, MPI prefix, environment, first error.

Used by the case runner, the test harness (tests/tsg_harness.py), the benchmarks and the scripts.

    command = lmp_command("in.case", {"rpm": 600}, nprocs=2)
    proc = subprocess.run(command, cwd=run_dir, env=lmp_environment())
    message = first_error(run_dir)          # the error LIGGGHTS reported, from the log or screen

Environment: TSG_LMP (the executable; default <repository>/build/lmp), TSG_MPIEXEC (mpirun).
"""
from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Mapping

from tsg_analysis.liggghts_log import parse_errors

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
