"""Runs of the paper-scale case from one developed state (dt-ladder/, yield-ladder/): per run, what its
thermo and squeeze records say about stability and cost over the same simulated time.

    .venv/bin/python studies/paper-400um/state_table.py [--end T] "dt / Rayleigh time" \
        runs/paper-400um-dt-ladder/dt_fraction-0.05=0.05 runs/paper-400um-dt-ladder/reference="0.1 (reference)" ...
"""
from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np

from tsg_analysis.liggghts_log import parse_thermo
from tsg_analysis.run import Run


def row(point: Path, label: str, end: float | None = None) -> str:
    """One table row over the run's log, or over its thermo intervals that end by `end` s."""
    run = Run(point)
    log = run.log
    blocks = [b for b in parse_thermo(log) if "Time" in b and len(b["Time"])]
    loops = re.findall(r"^Loop time of (\S+) on \d+ procs for (\d+) steps", log, re.M)
    builds_per_chunk = [int(n) for n in re.findall(r"^Neighbor list builds = (\d+)", log, re.M)]
    if end is not None:   # the chunks (one thermo interval each: one block, one loop time) that end by `end`
        chunks = 0
        while chunks < min(len(blocks), len(loops)) and float(blocks[chunks]["Time"][-1]) <= end * (1 + 1e-12):
            chunks += 1
        blocks, loops, builds_per_chunk = blocks[:chunks], loops[:chunks], builds_per_chunk[:chunks]
    column = {name: np.concatenate([b[name] for b in blocks]) for name in ("Time", "speed", "fast", "squeezes", "crossed",
                                                                          "e_excess")}
    start, end = float(column["Time"][0]), float(column["Time"][-1])
    seconds, steps = sum(float(t) for t, _ in loops), sum(int(n) for _, n in loops)
    builds = sum(builds_per_chunk)
    lost = re.search(r"ERROR: Lost atoms: (\d+) at the previous check.*?, (\d+) now", log)
    ledger = run.squeeze_ledger(start, end)
    release = ledger.release_speed_quantiles
    outcome = (f"stopped at t = {end:.4f} s: lost atoms ({lost.group(1)} → {lost.group(2)}, out of the domain)" if lost
               else "ran to the end, nothing lost" if "TSG-DONE" in log
               else f"runs on: to t = {end:.4f} s, nothing lost, no stop")
    return (f"| {label} | {outcome} | {1e3 * (end - start):.1f} | {steps} | {1e3 * seconds / steps:.1f} | "
            f"{1e3 * builds / steps:.0f} | {seconds / (end - start) / 3600:.1f} | "
            f"{int(column['fast'][-1] - column['fast'][0])} | {ledger.events} | {release[0.99]:.3g} / {release[1.0]:.3g} | "
            f"{ledger.peak_wall_quantiles[1.0]:.3g} | {int(column['crossed'][-1] - column['crossed'][0])} | "
            f"{float(column['speed'].max()):.3g} | {float(column['e_excess'].max()):.4f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("setting", help="the first column's title: what the runs vary")
    parser.add_argument("runs", nargs="+", metavar="RUN_DIR=LABEL", help="each run directory and its row label")
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
            print(row(Path(path), label, args.end))


if __name__ == "__main__":
    main()
