"""Particle imbalance and wall time with and without fix balance/x (docs/performance.md), side by side
in one invocation: the same case, seed and length run with equal slabs (balance_every 0) and with
moving cuts, alternately, for each rank count.

    .venv/bin/python benchmarks/balance.py --case periodic --np 2 4 --out runs/balance [--time 0.005]
    .venv/bin/python benchmarks/balance.py --case full --feed-at element:7 --np 2 4 --out runs/balance-full \
        --time 0.005 [--mesh-tolerance 5e-5] [-v feed_rate_kg_h 144]

Each run is `tsg_cases.run_case <case> --scale demo` with a short simulated time (periodic: the
start-up only, --time s, and a sampling window of one thermo interval; full: the start-up loop
stopped by t_max_startup = --time, which ends the run with its "no steady state" error: expected
here, the log up to there is what is measured). Reported per run, from log.lammps: LIGGGHTS' loop
time summed over all runs of the input, and the imbalance max/mean of the particles per rank that
LIGGGHTS prints after each run ("Nlocal: ave max min"), first and last chunk and the mean over the
chunks. Not a test: wall times depend on the machine and its load.
"""
from __future__ import annotations

import argparse
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

NLOCAL = re.compile(r"^Nlocal:\s+(\S+) ave (\S+) max (\S+) min", re.MULTILINE)
LOOP = re.compile(r"^Loop time of (\S+) on (\d+) procs for (\d+) steps", re.MULTILINE)


@dataclass
class Measured:
    loop_seconds: float
    steps: int
    imbalance: list[float]  # per run chunk, max / mean particles per rank

    def line(self) -> str:
        chunks = [f"{v:.2f}" for v in self.imbalance]
        mean = sum(self.imbalance) / len(self.imbalance) if self.imbalance else float("nan")
        shown = " ".join(chunks) if len(chunks) <= 8 else " ".join(chunks[:3] + ["..."] + chunks[-3:])
        return (f"loop {self.loop_seconds:8.1f} s for {self.steps} steps; imbalance mean {mean:.2f} "
                f"(per chunk: {shown})")


def measure(log: str) -> Measured:
    imbalance = [float(mx) / float(ave) for ave, mx, _ in NLOCAL.findall(log) if float(ave) > 0]
    loops = LOOP.findall(log)
    return Measured(sum(float(t) for t, _, _ in loops), sum(int(s) for _, _, s in loops), imbalance)


def run(case: str, out: Path, nprocs: int, balance_every: int, seconds: float, feed_at: str | None,
        mesh_tolerance: float | None, extra: list[tuple[str, str]]) -> Measured:
    command = [sys.executable, "-m", "tsg_cases.run_case", case, "--scale", "demo", "--out", str(out),
               "--np", str(nprocs), "-v", "balance_every", str(balance_every)]
    if mesh_tolerance:
        command += ["--mesh-tolerance", str(mesh_tolerance)]
    if case == "periodic":
        command += ["-v", "t_startup", str(seconds), "-v", "t_sample", str(seconds / 10)]
    else:
        command += ["-v", "t_max_startup", str(seconds)]
        if feed_at:
            command += ["--feed-at", feed_at]
    for name, value in extra:
        command += ["-v", name, value]
    proc = subprocess.run(command, capture_output=True, text=True)
    log = (out / "log.lammps").read_text(errors="replace") if (out / "log.lammps").exists() else ""
    expected_stop = case != "periodic" and "no steady state by t" in log
    if proc.returncode != 0 and not expected_stop:
        raise SystemExit(f"{' '.join(command)} failed (exit {proc.returncode}):\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    return measure(log)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--case", choices=["periodic", "full", "nonperiodic"], required=True)
    parser.add_argument("--np", type=int, nargs="+", default=[2, 4])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--time", type=float, default=0.005, help="simulated seconds per run")
    parser.add_argument("--balance-every", type=int, default=1000)
    parser.add_argument("--feed-at", default=None)
    parser.add_argument("--mesh-tolerance", type=float, default=None, help="m, instead of the demo scale's")
    parser.add_argument("-v", "--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"))
    args = parser.parse_args(argv)
    if args.time <= 0:
        parser.error(f"--time {args.time} is not allowed: simulated seconds per run, > 0")
    if args.balance_every < 1:
        parser.error(f"--balance-every {args.balance_every} is not allowed: steps, >= 1")
    print(f"{args.case} demo, {args.time} s simulated per run; wall times measured under the load of the moment, "
          "the two variants of a rank count run one after the other", flush=True)
    for nprocs in args.np:
        results = {}
        for every in (0, args.balance_every):
            label = "equal slabs" if every == 0 else f"balance/x every {every}"
            results[every] = run(args.case, args.out / f"np{nprocs}-b{every}", nprocs, every, args.time, args.feed_at,
                                 args.mesh_tolerance, args.var)
            print(f"np {nprocs}, {label:22s}: {results[every].line()}", flush=True)
        balanced, equal = results[args.balance_every], results[0]
        ratio = (balanced.loop_seconds / balanced.steps) / (equal.loop_seconds / equal.steps)
        print(f"np {nprocs}: loop time per step, balanced / equal slabs = {ratio:.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
