"""The case tools' rows of the bad-input campaign (tests/errors/README.md): sweep, free space, PSD."""
from __future__ import annotations

import os
from pathlib import Path

from badinput import ROOT, BadInput

MESH_DIR = str(Path(os.environ.get("TSG_BUILD_DIR", ROOT / "build")) / "meshes" / "consigma1-periodic-5um")
SWEEP = ["{python}", "-m", "tsg_cases.sweep"]
FREE = ["{python}", "-m", "tsg_cases.free_space"]
PSD = ["{python}", "-m", "tsg_cases.psd"]
# one job segment of cases/slurm/ outside SLURM (no successor is submitted), with the run directory in {tmp}/run
SEGMENT = ["env", "TSG_OUT={tmp}/run", "TSG_LAUNCH=", "TSG_LMP={lmp}", "TSG_RUN_CASE={python} -m tsg_cases.run_case"]


def fill(*options: str) -> list[str]:
    return [*FREE, "fill", MESH_DIR, "{tmp}/fill.in", "--x1", "0.0958", *options]


CASES: list[BadInput] = [
    BadInput("tools.sweep.misspelt", ("-v rmp", "did you mean rpm"),
             why="a misspelt override would run the whole matrix with the default",
             command=[*SWEEP, "write", "{tmp}/sweep", "-v", "rmp", "300"]),
    BadInput("tools.sweep.runner-set", ("-v mesh_dir", "set by the runner"),
             why="the runner sets the meshes", command=[*SWEEP, "write", "{tmp}/sweep", "-v", "mesh_dir", "/tmp"]),
    BadInput("tools.sweep.value", ("t_sample = -1 is not allowed",),
             why="an override no run can mean is refused before the matrix is written",
             command=[*SWEEP, "write", "{tmp}/sweep", "-v", "t_sample", "-1"]),
    BadInput("tools.sweep.np", ("--np 0", ">= 1"), why="no ranks", command=[*SWEEP, "write", "{tmp}/sweep", "--np", "0"]),
    BadInput("tools.sweep.replicas", ("--replicas 0", ">= 1"), why="no run per setting",
             command=[*SWEEP, "write", "{tmp}/sweep", "--replicas", "0"]),
    BadInput("tools.sweep.seeds", ("--seeds 2 2 is not allowed", "distinct fill seeds >= 1"), why="a seed twice",
             command=[*SWEEP, "write", "{tmp}/sweep", "--seeds", "2", "2"]),
    BadInput("tools.sweep.seeds-and-replicas", ("not allowed with argument",), why="two ways to name the seeds",
             command=[*SWEEP, "write", "{tmp}/sweep", "--seeds", "4", "--replicas", "3"]),
    BadInput("tools.sweep.only-unknown", ("--only diameter-400um", "use names of the matrix"),
             why="a setting the matrix does not have would silently write nothing",
             command=[*SWEEP, "write", "{tmp}/sweep", "--only", "reference", "diameter-400um"]),
    BadInput("tools.sweep.report-no-reference", ("the reference has no finished run",),
             why="differences need the reference", files={"sweep/runs.txt": "reference\n", "sweep/reference/sweep.json": "{}\n"},
             command=[*SWEEP, "report", "{tmp}/sweep"]),
    BadInput("tools.sweep.report-start", ("--start -0.1 is not allowed", "a time in s >= 0, or 'auto'"),
             why="a window cannot start before the run", files={"sweep/runs.txt": "reference\n", "sweep/reference/sweep.json": "{}\n"},
             command=[*SWEEP, "report", "{tmp}/sweep", "--start", "-0.1"]),
    BadInput("tools.sweep.report-parts", ("--parts 0 is not allowed", ">= 1"),
             why="a window in no parts", files={"sweep/runs.txt": "reference\n", "sweep/reference/sweep.json": "{}\n"},
             command=[*SWEEP, "report", "{tmp}/sweep", "--parts", "0"]),
    BadInput("tools.sweep.run-not-a-sweep", ("is not a sweep directory", "no runs.txt"),
             why="run on a directory that write did not make", command=[*SWEEP, "run", "{tmp}"]),
    BadInput("tools.sweep.status-not-a-sweep", ("is not a sweep directory",),
             why="status on a directory that write did not make", command=[*SWEEP, "status", "{tmp}"]),
    BadInput("tools.sweep.out-is-a-file", ("tsg-sweep: error", "{tmp}/afile"),
             why="the sweep directory is a file", files={"afile": "x\n"},
             command=[*SWEEP, "write", "{tmp}/afile"], intact=("afile",)),
    BadInput("tools.free-space.no-meshes", ("{tmp}/screw1.stl does not exist", "build the meshes"),
             why="the fill needs the built meshes", command=[*FREE, "fill", "{tmp}", "{tmp}/fill.in",
                                                             "--mass", "1e-3", "--d-mean", "1e-3", "--x1", "0.1"]),
    BadInput("tools.free-space.mass", ("--mass -0.001 is not allowed", "> 0"), why="a negative hold-up mass",
             command=fill("--mass", "-0.001", "--d-mean", "1e-3")),
    BadInput("tools.free-space.d-mean", ("--d-mean 0.0 is not allowed",), why="particles of no size",
             command=fill("--mass", "1e-3", "--d-mean", "0")),
    BadInput("tools.free-space.sigma", ("--sigma -0.1 is not allowed",), why="a negative PSD width",
             command=fill("--mass", "1e-3", "--d-mean", "1e-3", "--sigma", "-0.1")),
    BadInput("tools.free-space.density", ("--density 0.0 is not allowed",), why="a density of zero",
             command=fill("--mass", "1e-3", "--d-mean", "1e-3", "--density", "0")),
    BadInput("tools.free-space.range", ("--x1 0.0958 is not allowed", "must be > --x0 0.2"),
             why="an empty axial range", command=fill("--mass", "1e-3", "--d-mean", "1e-3", "--x0", "0.2")),
    BadInput("tools.free-space.feed-side", ("--side 0.0", "side > 0"), why="feed cubes of no size",
             command=[*FREE, "feed", MESH_DIR, "{tmp}/feed.in", "--x0", "0.0", "--x1", "0.03", "--side", "0"]),
    BadInput("tools.psd.sigma", ("relative_sigma = -0.1 is not allowed",), why="a negative PSD width",
             command=[*PSD, "write", "{tmp}/psd.in", "-0.1"]),
    BadInput("tools.psd.classes", ("classes = 0", "must be in [1, 15]"), why="a PSD of no classes",
             command=[*PSD, "write", "{tmp}/psd.in", "0.05", "--classes", "0"]),
    BadInput("tools.psd.out-is-a-directory", ("tsg-psd: error", "Is a directory"),
             why="the include file is a directory", command=[*PSD, "write", "{tmp}", "0.05"]),
    BadInput("tools.segment.prepare-option", ("preparation failed: tsg-run-case periodic --scale nope", "invalid choice: 'nope'"),
             why="a job chain whose run cannot be prepared stops at once (FAILED), before any lmp",
             command=[*SEGMENT, "TSG_PREPARE=--scale nope", "{root}/cases/slurm/segment.sh", "periodic", "JOB"]),
    BadInput("tools.segment.prepare-changed",
             ('TSG_PREPARE = "--scale demo --seed 2" is not allowed', 'was prepared with "--scale demo --seed 1"', "another TSG_OUT"),
             why="a chain continues the run it prepared: other preparation options would silently not apply",
             files={"run/lmp.vars": "t_sample 0.2\n", "run/prepared-with": "--scale demo --seed 1\n"},
             command=[*SEGMENT, "TSG_PREPARE=--scale demo --seed 2", "{root}/cases/slurm/segment.sh", "periodic", "JOB"],
             intact=("run/lmp.vars", "run/prepared-with")),
    BadInput("tools.segment.keep-restarts", ('TSG_KEEP_RESTARTS = "two" is not allowed', "a whole number", "0 keeps all"),
             why="a misspelt count would otherwise be found only after the segment, with restart files at stake",
             command=[*SEGMENT, "TSG_KEEP_RESTARTS=two", "{root}/cases/slurm/segment.sh", "periodic", "JOB"]),
    BadInput("tools.prune-restarts.keep", ('KEEP = "-1" is not allowed', "a whole number"),
             why="a negative count of restart files to keep",
             files={"run/restart.200": "x", "run/log.lammps": "   400 0.1 1 2 3 4 5 6 7 8\n"},
             command=["{root}/cases/slurm/prune-restarts.sh", "{tmp}/run", "-1"], intact=("run/restart.200",)),
]
