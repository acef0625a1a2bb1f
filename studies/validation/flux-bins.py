"""The domain flux Σ m v_x / L of periodic runs in time bins, kg/h: a quick look at slow transients.

    .venv/bin/python studies/validation/flux-bins.py WIDTH_S RUN_DIR [RUN_DIR ...] [--replicas]

Each element block of RUN_DIR/elements.txt gives one flux value (tsg_analysis.profiles.domain_flux);
a bin's value is the mean over the blocks that end in (t, t + WIDTH_S]. Bins start at t = 0, so the
first one holds the blocks after the run's start-up only. With --replicas the runs are replicas (fill
seeds) of one setting, and a last line gives each bin's replica mean ± 95 % (t_{R-1} s/sqrt(R), one
independent value per run: tsg_analysis.uncertainty.replica_means). Used for docs/validation.md.
"""
from __future__ import annotations

import sys

import numpy as np

from tsg_analysis.massflow import SECONDS_PER_HOUR
from tsg_analysis.profiles import domain_flux
from tsg_analysis.run import Run
from tsg_analysis.uncertainty import Estimate, replica_means


def main(argv: list[str]) -> int:
    replicas = "--replicas" in argv
    argv = [a for a in argv if a != "--replicas"]
    if len(argv) < 2:
        raise SystemExit(__doc__)
    width = float(argv[0])
    if not width > 0:
        raise SystemExit(f"WIDTH_S {argv[0]} is not allowed: a bin width in s, > 0")
    per_run: list[dict[float, float]] = []
    for run in map(Run, argv[1:]):
        _, ends = run.block_times   # a run still going: its complete blocks
        flux = domain_flux(run.elements, run.zones, np.ones(len(ends), bool)) * SECONDS_PER_HOUR
        starts = np.arange(0.0, ends[-1], width)
        values = {float(t): flux[(ends > t) & (ends <= t + width)] for t in starts}
        per_run.append({t: float(v.mean()) for t, v in values.items() if len(v)})
        print(run.path, " ".join(f"{t:.2f}-{t + width:.2f}: {v:.2f}" for t, v in per_run[-1].items()))
    if replicas:
        shared = sorted(set.intersection(*(set(bins) for bins in per_run)))
        cells = []
        for t in shared:
            combined = replica_means([Estimate(run[t], np.nan, 1, 1.0, np.nan) for run in per_run])
            cells.append(f"{t:.2f}-{t + width:.2f}: {combined.mean:.2f} ± {combined.half_width:.2f}")
        print(f"replica mean ± 95 % ({len(per_run)} runs)", " ".join(cells))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
