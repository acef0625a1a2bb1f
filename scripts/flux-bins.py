"""The domain flux Σ m v_x / L of periodic runs in time bins, kg/h: a quick look at slow transients.

    .venv/bin/python scripts/flux-bins.py WIDTH_S RUN_DIR [RUN_DIR ...]

Each element block of RUN_DIR/elements.txt gives one flux value (tsg_analysis.validation.domain_flux);
a bin's value is the mean over the blocks that end in (t, t + WIDTH_S]. Bins start at t = 0, so the
first one holds the blocks after the run's start-up only. Used for docs/validation.md.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "analysis"))
from tsg_analysis.accuracy import block_times  # noqa: E402
from tsg_analysis.run_files import read_element_statistics, read_zones  # noqa: E402
from tsg_analysis.validation import domain_flux  # noqa: E402

SECONDS_PER_HOUR = 3600.0


def main(argv: list[str]) -> int:
    if len(argv) < 2:
        raise SystemExit(__doc__)
    width = float(argv[0])
    if not width > 0:
        raise SystemExit(f"WIDTH_S {argv[0]} is not allowed: a bin width in s, > 0")
    for run_dir in map(Path, argv[1:]):
        stats = read_element_statistics(run_dir / "elements.txt")
        _, ends = block_times(run_dir)
        blocks = min(len(ends), stats.column("mass").shape[0])   # a run still going: its complete blocks
        ends = ends[:blocks]
        flux = domain_flux(stats, read_zones(run_dir / "zones.txt"), np.ones(len(ends), bool))[:blocks] * SECONDS_PER_HOUR
        starts = np.arange(0.0, ends[-1], width)
        values = [flux[(ends > t) & (ends <= t + width)] for t in starts]
        print(run_dir, " ".join(f"{t:.2f}-{t + width:.2f}: {v.mean():.2f}" for t, v in zip(starts, values) if len(v)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
