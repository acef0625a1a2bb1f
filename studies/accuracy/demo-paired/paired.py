"""Would pairing decide the 5 % question? Each replica of a point continues the same kept state as the
reference replica of its seed (tsg-accuracy --from-states), so a pair shares its start; the difference of
a pair's window means could then cancel the slow fluctuation both runs share.

    LC_ALL=C.UTF-8 .venv/bin/python studies/accuracy/demo-paired/paired.py STUDY POINT [SEEDS]

Per key quantity: the independent-replica error of tsg-accuracy (uncertainty.difference of the combined
replicas) beside the paired one (Student's t over the R per-seed differences, R - 1 degrees of freedom)
and the windows' own noise (sqrt of the sum of both runs' time-series variances over R, the floor that
uncertainty.replica_means applies), all as 95 % half-widths relative to the reference mean.
"""
from __future__ import annotations

import math
import sys

import numpy as np

from tsg_analysis.run import Run
from tsg_analysis.uncertainty import combine_replicas, difference, t_quantile


def main(study: str, point: str, seeds: int = 3) -> None:
    refs = [Run(f"{study}/reference/seed-{k}").key_estimates() for k in range(1, seeds + 1)]
    pts = [Run(f"{study}/{point}/seed-{k}").key_estimates() for k in range(1, seeds + 1)]
    t = t_quantile(seeds - 1)
    print(f"{point} against the reference, {seeds} pairs (seed k of both continues kept state k); 95 % half-widths "
          "relative to the reference mean")
    print(f"{'quantity':<15}{'scope':<11}{'reference':>10}  {'independent':>11}  {'paired difference':>20}  {'windows':>8}")
    for key in refs[0]:
        if not all(key in e for e in refs + pts):
            continue
        r = np.array([e[key].mean for e in refs])
        p = np.array([e[key].mean for e in pts])
        noise = np.array([e[key].standard_error for e in refs + pts])
        independent = difference(combine_replicas([e[key] for e in refs]), combine_replicas([e[key] for e in pts]))
        d = p - r
        scale = abs(r.mean())
        paired = t * d.std(ddof=1) / math.sqrt(seeds) / scale
        windows = t * math.sqrt(float(np.sum(noise**2))) / seeds / scale
        print(f"{key[0][:14]:<15}{str(key[1])[:10]:<11}{r.mean():>10.4g}  ±{independent.half_width / scale:>9.1%}  "
              f"{d.mean() / scale:>+8.1%} ±{paired:>9.1%}  ±{windows:>6.1%}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], *(int(a) for a in sys.argv[3:]))
