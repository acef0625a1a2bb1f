"""Cost of the guards and the wall-overlap monitor (fix check/contact, docs/stability.md) on the
periodic demo case, measured side by side in one invocation.

    .venv/bin/python benchmarks/guards_cost.py --before /work/lmp-main/lmp --before-cases /work/main/cases
        [--steps 1000] [--repeat 3] [--thermo-every 500] [--screw-drive corotating]

Two variants of the same run (cases/in.tsg_periodic at demo scale, from the same fill, the same
number of steps), interleaved --repeat times:
  before: an lmp and case inputs without the guards (check/contact only estimates the step and
          reads the pair overlaps every thermo interval; wall/gran/corotating records no overlaps);
  guards: this build with cases/include/guards.in: the per-step motion guard, the pair and wall
          overlap monitors at every check, the corotating fix's per-contact overlap record. The
          thresholds are raised out of reach so that both variants run every step (the demo fill
          trips the default guards within a few milliseconds: docs/stability.md).
Prints LIGGGHTS' loop time and the process CPU time per step of every run, the medians and the
relative difference. Not a test: the numbers depend on the machine and its load.
"""
from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from tsg_cases.launcher import lmp_executable

ROOT = Path(__file__).resolve().parents[1]

RELAXED = {"guard_max_speed": 1e9, "guard_max_pair_overlap": 1e9, "guard_max_wall_overlap": 1e9}


def prepare(out: Path) -> Path:
    """A demo-scale periodic run directory (meshes, zones, fill) made by run_case.py with 0 steps."""
    subprocess.run([sys.executable, str(ROOT / "cases" / "run_case.py"), "periodic", "--scale", "demo", "--out",
                    str(out), "-v", "t_startup", "0", "-v", "t_sample", "0"] + sum((["-v", k, str(v)] for k, v in RELAXED.items()), []),
                   check=True, capture_output=True, text=True)
    return out


def run(lmp: str, cases: Path, prepared: Path, steps: int, thermo_every: int, drive: str,
        extra: dict[str, object], workdir: Path) -> tuple[float, float]:
    """(loop seconds per step, CPU seconds per step) of one run."""
    workdir.mkdir(parents=True, exist_ok=True)
    dt = float(re.search(r"time step (\S+) s", (prepared / "log.lammps").read_text(errors="replace")).group(1))
    mesh_dir = re.search(r"mesh_dir=(\S+)", (prepared / "log.lammps").read_text(errors="replace")).group(1)
    variables = {"case_dir": cases, "out_dir": workdir, "mesh_dir": mesh_dir,
                 "zones_file": prepared / "zones.txt", "fill_file": prepared / "fill.in", "d_mean": 0.001,
                 "dt_fraction": 0.2, "thermo_every": thermo_every, "stats_every": thermo_every,
                 "t_startup": steps * dt, "t_sample": 0, "screw_drive": drive, **extra}
    command = [lmp, "-in", str(cases / "in.tsg_periodic"), "-log", "log.lammps", "-echo", "none"]
    for name, value in variables.items():
        command += ["-var", name, str(value)]
    start = os.times()
    subprocess.run(command, cwd=workdir, check=True, capture_output=True, text=True)
    end = os.times()
    log = (workdir / "log.lammps").read_text(errors="replace")
    loops = re.findall(r"Loop time of (\S+) on \d+ procs for (\d+) steps", log)
    loop_seconds = sum(float(t) for t, n in loops)
    loop_steps = sum(int(n) for t, n in loops)
    cpu = (end.children_user - start.children_user) + (end.children_system - start.children_system)
    return loop_seconds / loop_steps, cpu / loop_steps


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--before", required=True, help="lmp without the guards")
    parser.add_argument("--before-cases", type=Path, required=True, help="its cases/ directory")
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--thermo-every", type=int, default=500)
    parser.add_argument("--screw-drive", default="corotating", choices=["corotating", "stock"])
    args = parser.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="guards_cost_"))
    prepared = prepare(work / "prepared")
    variants = {"before": (args.before, args.before_cases, {}),
                "guards": (lmp_executable(), ROOT / "cases", RELAXED)}
    results: dict[str, list[tuple[float, float]]] = {name: [] for name in variants}
    for k in range(args.repeat):
        for name, (lmp, cases, extra) in variants.items():
            results[name].append(run(lmp, cases, prepared, args.steps, args.thermo_every, args.screw_drive, extra,
                                     work / f"{name}{k}"))
            loop, cpu = results[name][-1]
            print(f"{name:7s} repeat {k}: loop {1e3 * loop:.3f} ms/step, cpu {1e3 * cpu:.3f} ms/step", flush=True)
    medians = {name: (statistics.median(l for l, c in r), statistics.median(c for l, c in r))
               for name, r in results.items()}
    for name, (loop, cpu) in medians.items():
        print(f"median {name:7s}: loop {1e3 * loop:.3f} ms/step, cpu {1e3 * cpu:.3f} ms/step")
    print(f"guards / before - 1: loop {100 * (medians['guards'][0] / medians['before'][0] - 1):+.2f} %, "
          f"cpu {100 * (medians['guards'][1] / medians['before'][1] - 1):+.2f} % "
          f"({args.steps} steps, {args.screw_drive} screws, check every {args.thermo_every} steps; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load {os.getloadavg()[0]:.1f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
