"""Runs of the paper-scale case from one developed state (dt-ladder/, yield-ladder/): per run, what its
thermo and squeeze records say about stability and cost over the same simulated time.

    .venv/bin/python studies/paper-400um/state_table.py [--start T0] [--end T] "dt / Rayleigh time" \
        runs/paper-400um-dt-ladder/dt_fraction-0.05=0.05 runs/paper-400um-dt-ladder/reference="0.1 (reference)" ...
"""
from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np

from tsg_analysis.liggghts_log import parse_thermo
from tsg_analysis.run import Run


def chunks(run: Run, start: float | None, end: float | None) -> list[tuple[dict[str, np.ndarray], float, int, int]]:
    """The run's thermo intervals (thermo block, loop seconds, steps, neighbour-list builds) that lie in
    [start, end] s, over every segment's log; a segment continued from a restart file replaces the
    earlier segment's intervals from that restart on."""
    kept: list[tuple[dict[str, np.ndarray], float, int, int]] = []
    for log in run.segment_logs:
        loops = re.findall(r"^Loop time of (\S+) on \d+ procs for (\d+) steps", log, re.M)
        builds = [int(n) for n in re.findall(r"^Neighbor list builds = (\d+)", log, re.M)]
        complete = parse_thermo(log)[:min(len(loops), len(builds))]   # a killed segment's last block has no loop line
        new = [(block, float(t), int(n), b) for block, (t, n), b in zip(complete, loops, builds)
               if "Time" in block and len(block["Time"])]
        if new:
            first = float(new[0][0]["Time"][0])
            kept = [c for c in kept if float(c[0]["Time"][-1]) <= first * (1 + 1e-12)]
        kept += new
    return [c for c in kept if (start is None or float(c[0]["Time"][0]) >= start * (1 - 1e-12))
            and (end is None or float(c[0]["Time"][-1]) <= end * (1 + 1e-12))]


def row(point: Path, label: str, start: float | None = None, end: float | None = None) -> str:
    """One table row over the run's thermo intervals in [start, end] s (all when None)."""
    run = Run(point)
    log = run.log
    window = chunks(run, start, end)
    if not window:
        raise SystemExit(f"{point}: no complete thermo interval in [{start}, {end}] s")
    column = {name: np.concatenate([c[0][name] for c in window]) for name in ("Time", "speed", "e_excess")}
    counted = {name: sum(float(c[0][name][-1] - c[0][name][0]) for c in window) for name in ("fast", "crossed")}
    start, end = float(column["Time"][0]), float(column["Time"][-1])
    seconds, steps, builds = sum(c[1] for c in window), sum(c[2] for c in window), sum(c[3] for c in window)
    lost = re.search(r"ERROR: Lost atoms: (\d+) at the previous check.*?, (\d+) now", log)
    ledger = run.squeeze_ledger(start, end)
    release = ledger.release_speed_quantiles
    run_end = float(chunks(run, None, None)[-1][0]["Time"][-1])
    the_run = "ran to its end" if "TSG-DONE" in log else f"runs on to t = {run_end:.4f} s"
    outcome = (f"the window ends inside the run ({the_run}): nothing lost in it" if end < run_end * (1 - 1e-12)
               else f"stopped at t = {end:.4f} s: lost atoms ({lost.group(1)} → {lost.group(2)}, out of the domain)"
               if lost else "ran to the end, nothing lost" if "TSG-DONE" in log
               else f"runs on: to t = {end:.4f} s, nothing lost, no stop")
    return (f"| {label} | {outcome} | {1e3 * (end - start):.1f} | {steps} | {1e3 * seconds / steps:.1f} | "
            f"{1e3 * builds / steps:.0f} | {seconds / (end - start) / 3600:.1f} | "
            f"{int(counted['fast'])} | {ledger.events} | {release[0.99]:.3g} / {release[1.0]:.3g} | "
            f"{ledger.peak_wall_quantiles[1.0]:.3g} | {int(counted['crossed'])} | "
            f"{float(column['speed'].max()):.3g} | {float(column['e_excess'].max()):.4f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("setting", help="the first column's title: what the runs vary")
    parser.add_argument("runs", nargs="+", metavar="RUN_DIR=LABEL", help="each run directory and its row label")
    parser.add_argument("--start", type=float, help="only the thermo intervals that begin at or after this time, s")
    parser.add_argument("--end", type=float, help="only the thermo intervals that end by this time, s (runs of "
                                                  "different lengths over one window)")
    args = parser.parse_args()
    print(f"| {args.setting} | outcome | simulated ms | steps | ms/step | neighbour builds per 1 000 steps | "
          "core-h per simulated s | fast events | squeezes | release speed 99 % / max, m/s | peak wall δ/R max | "
          "wall crossings | max speed, m/s | max energy excess |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for item in args.runs:
        path, _, label = item.partition("=")
        if not label:
            parser.error(f"{item}: give RUN_DIR=LABEL")
        if (Path(path) / "log.lammps").is_file():
            print(row(Path(path), label, args.start, args.end))


if __name__ == "__main__":
    main()
