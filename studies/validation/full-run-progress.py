"""A full-case run's progress, per window of simulated time: the particles inside at the window's end
and the two mass-flow sensors' means (MFS_1 after the feed, MFS_2 before the outlet), kg/h.

    .venv/bin/python studies/validation/full-run-progress.py RUN_DIR [WINDOW_S]     # default 1 s

The tables of docs/validation.md, "Periodic against full". Particles from the log's thermo rows
(log.upto-*.lammps and log.lammps of a segmented run); flows from massflow.txt
(tsg_analysis.massflow.window_means, windows from t = 0).
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from tsg_analysis.liggghts_log import parse_thermo
from tsg_analysis.run import Run
from tsg_analysis.run_files import AnalysisInputError


def particles_over_steps(run: Path) -> tuple[np.ndarray, np.ndarray]:
    """(step, atoms) of every thermo row of the run's logs, later segments winning where they overlap
    (the log's Time column restarts with each segment: the time comes from the mass-flow record's steps)."""
    rows: dict[int, float] = {}
    for log in Run(run).segment_logs:
        for block in parse_thermo(log):
            if "Atoms" in block:
                rows.update({int(s): float(a) for s, a in zip(block["Step"], block["Atoms"])})
    steps = np.array(sorted(rows))
    return steps, np.array([rows[s] for s in steps])


def main(argv: list[str]) -> int:
    if not 1 <= len(argv) <= 2:
        print(__doc__, file=sys.stderr)
        return 2
    run, window = Path(argv[0]), float(argv[1]) if len(argv) > 1 else 1.0
    if not window > 0:
        print(f"WINDOW_S = {window} is not allowed: a window in s, > 0", file=sys.stderr)
        return 2
    try:
        record, clock = Run(run).massflow, Run(run).clock
    except AnalysisInputError as problem:
        print(f"full-run-progress: {problem}", file=sys.stderr)
        return 2
    steps, atoms = particles_over_steps(run)
    time = clock.time(steps)
    edges = np.arange(0.0, record.time[-1] + 1e-12, window)
    print("| t (s) | particles at the end | MFS_1 (kg/h) | MFS_2 (kg/h) |\n|---|---|---|---|")
    for start in edges:
        end = min(start + window, float(record.time[-1]))
        inside = (record.time > start) & (record.time <= end)
        if end <= start or not inside.any():
            continue
        durations = np.diff(record.time, prepend=0.0)[inside]
        flows = (record.flow[inside] * durations[:, None]).sum(axis=0) / durations.sum()
        count = atoms[np.searchsorted(time, end, side="right") - 1]
        print(f"| {start:g}–{end:.4g} | {count:,.0f} | {flows[0]:.2f} | {flows[1]:.2f} |".replace(",", " "))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
