"""The full granulator on 1 and 2 (or more) ranks from the same state in motion, side by side.

    .venv/bin/python benchmarks/full_ranks.py [--np 1 2] [--steps 6000] [--repeat 2] [--work DIR] [--json FILE]
        [--baseline LMP]

The state is the 1.5 mm full run kept for the validation (studies/validation/full-demo-d15: ≈ 5 500
particles spread over the whole machine, screws turning, feed on). Each row continues it for --steps
steps with cases/in.tsg_full as it is; the multi-rank rows twice: with the load balance of the open
cases (fix balance/x every 1000 steps, the default) and with equal slabs (-var balance_every 0). Printed:
ms/step (LIGGGHTS' loop time over the chunks after the first, median and range over the repeats),
speed-up against 1 rank, and LIGGGHTS' share of the loop in fixes ("Other"; LIGGGHTS 3.8 counts the
fixes there). --baseline adds the balanced multi-rank rows of another lmp (e.g. one built without
src-liggghts-eepa/patches/fix-mesh-cpp.patch) to the same table. This is the measurement behind
docs/performance.md, "Static meshes and moving cuts".
Not a test: wall-clock numbers depend on the machine and its load (recorded in the output).
"""
from __future__ import annotations

import argparse
import json
import lzma
import os
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

# a sibling (python puts the script's folder first on its path): mpi, machine: one way to launch lmp and to name the machine
import paper_cost

ROOT = paper_cost.ROOT
KEPT = ROOT / "studies" / "validation" / "full-demo-d15"
MESH_NAME = "consigma1-full-4um-c2.1-4.2mm-g2.1mm"
MESH_OPTIONS = ["--tolerance", "4e-06", "--clearance", "0.0021", "--screw-clearance", "0.0042", "--disc-gap", "0.0021"]
CHUNK = 2000   # the case runs in chunks of thermo_every steps (params.json of the kept run)


def unpack(work: Path) -> tuple[Path, int]:
    """The kept restart file and the run's side files in work/state; the restart's step."""
    state = work / "state"
    restarts = sorted(KEPT.glob("restart.*.xz"))
    if len(restarts) != 1:
        raise SystemExit(f"expected one restart.*.xz in {KEPT}, found {len(restarts)}")
    step = int(restarts[0].name.split(".")[1])
    restart = state / f"restart.{step}"
    if not restart.exists():
        state.mkdir(parents=True, exist_ok=True)
        with lzma.open(restarts[0]) as packed, open(restart, "wb") as plain:
            shutil.copyfileobj(packed, plain)
        with lzma.open(KEPT / "log.lammps.xz") as packed:
            (state / "log.lammps").write_bytes(packed.read())
    return restart, step


def time_step(log: str) -> float:
    """dt from two consecutive thermo rows of the kept log (columns Step and Time)."""
    rows = re.findall(r"^\s*(\d+)\s+([0-9.eE+-]+)\s+\d+\s", log, re.M)
    for (s1, t1), (s2, t2) in zip(rows, rows[1:]):
        if int(s2) > int(s1) and float(t2) > float(t1):
            return (float(t2) - float(t1)) / (int(s2) - int(s1))
    raise SystemExit("no two consecutive thermo rows in the kept log to read the time step from")


def mesh_dir(python: str) -> Path:
    meshes = ROOT / "build" / "meshes" / MESH_NAME
    if not (meshes / "zones.txt").exists():
        subprocess.run([python, "-m", "tsg_meshes", "build", "consigma1-full", str(meshes), *MESH_OPTIONS], check=True)
    return meshes


def run(lmp: str, np_ranks: int, balance_every: int, restart: Path, restart_step: int, steps: int, dt: float,
        meshes: Path, workdir: Path) -> tuple[float, float]:
    """ms/step over the chunks after the first, and the mean 'Other' share of the loop, %."""
    if workdir.exists():
        shutil.rmtree(workdir)
    workdir.mkdir(parents=True)
    for name in ("feed.in", "phase.in", "zones.txt", "machine.in", "holdup.txt"):
        shutil.copy(KEPT / name, workdir / name)
    given = json.loads((KEPT / "params.json").read_text())["variables"]
    steady_step = int(re.search(r"steady_step index (\d+)", (KEPT / "phase.in").read_text()).group(1))
    skip = {"out_dir", "procs_x", "restart_every", "case_dir", "feed_file", "mesh_dir", "t_sample"}
    variables = {k: v for k, v in given.items() if k not in skip}
    variables.update({"case_dir": ROOT / "cases", "out_dir": workdir, "feed_file": workdir / "feed.in",
                      "mesh_dir": meshes, "procs_x": np_ranks, "restart_every": 10 ** 9, "start": "restart",
                      "restart_file": restart, "balance_every": balance_every,
                      # the run ends steps after the restart: the sampling ends t_sample after steady_step
                      "t_sample": (restart_step + steps - steady_step + 0.5) * dt})
    command = paper_cost.mpi(lmp, np_ranks) + ["-in", str(ROOT / "cases" / "in.tsg_full"), "-echo", "none"]
    log = paper_cost.lmp_run(command, workdir, variables)
    loops = re.findall(r"Loop time of (\S+) on \d+ procs for (\d+) steps", log)
    other = [float(v) for v in re.findall(r"^Other\s+time \(%\) = \S+ \((\S+)\)", log, re.M)]
    if len(loops) < 2:
        raise SystemExit(f"{workdir}: fewer than two chunks ran ({len(loops)}); raise --steps")
    loop_s = sum(float(t) for t, _ in loops[1:])
    loop_steps = sum(int(n) for _, n in loops[1:])
    return 1e3 * loop_s / loop_steps, statistics.mean(other[1:])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--lmp", default=os.environ.get("TSG_LMP", str(ROOT / "build" / "lmp")))
    parser.add_argument("--np", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--steps", type=int, default=6000, help=f"steps per run, a multiple of {CHUNK}, >= {2 * CHUNK}")
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--work", type=Path, default=None, help="keeps the unpacked state between calls")
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--baseline", default=None, help="another lmp whose balanced multi-rank rows are added")
    args = parser.parse_args(argv)
    if args.steps % CHUNK or args.steps < 2 * CHUNK:
        parser.error(f"--steps {args.steps} is not allowed: a multiple of {CHUNK}, at least {2 * CHUNK}")
    if 1 not in args.np:
        parser.error("--np must include 1 (the speed-up is against 1 rank)")
    work = args.work or Path(tempfile.mkdtemp(prefix="full_ranks_"))
    restart, restart_step = unpack(work)
    dt = time_step((work / "state" / "log.lammps").read_text(errors="replace"))
    meshes = mesh_dir(sys.executable)
    print(f"command: {' '.join(shlex.quote(a) for a in [sys.executable] + sys.argv)}")
    print(f"machine: {paper_cost.machine()}", flush=True)
    # (lmp label, ranks, balance_every)
    settings = [("this", n, 1000 if n > 1 else 0) for n in args.np] + [("this", n, 0) for n in args.np if n > 1]
    if args.baseline:
        print(f"baseline lmp: {args.baseline}")
        settings += [("baseline", n, 1000) for n in args.np if n > 1]
    binary = {"this": args.lmp, "baseline": args.baseline}
    ms: dict[tuple[str, int, int], list[float]] = {s: [] for s in settings}
    other: dict[tuple[str, int, int], list[float]] = {s: [] for s in settings}
    for repeat in range(args.repeat):
        for setting in settings:
            label, n, every = setting
            t, share = run(binary[label], n, every, restart, restart_step, args.steps, dt, meshes,
                           work / f"{label}-np{n}-balance{every}-{repeat}")
            ms[setting].append(t)
            other[setting].append(share)
            print(f"  #{repeat} {label} lmp, {n} rank(s), balance_every {every}: {t:.3f} ms/step, fixes {share:.0f} % "
                  "of the loop", flush=True)
    serial = statistics.median(ms[("this", 1, 0)])
    rows = []
    print(f"\nfull granulator from {restart.name} ({KEPT.relative_to(ROOT)}), {args.steps} steps, "
          f"{args.repeat} repeat(s), the first {CHUNK}-step chunk of each run left out:")
    print("| lmp | ranks | cuts | ms/step (median; min-max) | speed-up | fixes' share of the loop |")
    print("|---|---|---|---|---|---|")
    for setting in settings:
        label, n, every = setting
        v = ms[setting]
        cuts = "—" if n == 1 else ("balance/x every 1000" if every else "equal slabs")
        row = {"lmp": binary[label], "np": n, "balance_every": every,
               "ms_per_step": {"min": min(v), "median": statistics.median(v), "max": max(v), "n": len(v)},
               "speed_up": serial / statistics.median(v), "other_percent": statistics.median(other[setting])}
        rows.append(row)
        print(f"| {label} | {n} | {cuts} | {row['ms_per_step']['median']:.2f} ({min(v):.2f}-{max(v):.2f}) | "
              f"{row['speed_up']:.2f} | {row['other_percent']:.0f} % |")
    end = paper_cost.machine()
    print(f"\nmachine at the end: {end}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"command": [sys.executable] + sys.argv, "machine_at_end": end,
                                         "lmp": args.lmp, "steps": args.steps, "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
