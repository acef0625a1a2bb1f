"""The domain flux Σ m v_x / L of periodic runs in time bins, kg/h: a quick look at slow transients.

    .venv/bin/python scripts/flux-bins.py WIDTH_S RUN_DIR [RUN_DIR ...] [--replicas]

Each element block of RUN_DIR/elements.txt gives one flux value (tsg_analysis.validation.domain_flux);
a bin's value is the mean over the blocks that end in (t, t + WIDTH_S]. Bins start at t = 0, so the
first one holds the blocks after the run's start-up only. With --replicas the runs are replicas (fill
seeds) of one setting, and a last line gives each bin's replica mean ± 95 % (t_{R-1} s/sqrt(R), one
independent value per run: tsg_analysis.uncertainty.replica_means). Used for docs/validation.md.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "analysis"))
from tsg_analysis.accuracy import block_times  # noqa: E402
from tsg_analysis.run_files import read_element_statistics, read_zones  # noqa: E402
from tsg_analysis.uncertainty import Estimate, replica_means  # noqa: E402
from tsg_analysis.validation import domain_flux  # noqa: E402

SECONDS_PER_HOUR = 3600.0


def main(argv: list[str]) -> int:
    replicas = "--replicas" in argv
    argv = [a for a in argv if a != "--replicas"]
    if len(argv) < 2:
        raise SystemExit(__doc__)
    width = float(argv[0])
    if not width > 0:
        raise SystemExit(f"WIDTH_S {argv[0]} is not allowed: a bin width in s, > 0")
    per_run: list[dict[float, float]] = []
    for run_dir in map(Path, argv[1:]):
        stats = read_element_statistics(run_dir / "elements.txt")
        _, ends = block_times(run_dir)
        blocks = min(len(ends), stats.column("mass").shape[0])   # a run still going: its complete blocks
        ends = ends[:blocks]
        flux = domain_flux(stats, read_zones(run_dir / "zones.txt"), np.ones(len(ends), bool))[:blocks] * SECONDS_PER_HOUR
        starts = np.arange(0.0, ends[-1], width)
        values = {float(t): flux[(ends > t) & (ends <= t + width)] for t in starts}
        per_run.append({t: float(v.mean()) for t, v in values.items() if len(v)})
        print(run_dir, " ".join(f"{t:.2f}-{t + width:.2f}: {v:.2f}" for t, v in per_run[-1].items()))
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
