"""A setting against the reference, paired by state (treatment-2.7g/, dt-paired-2.7g/). Each run of the
setting continues a state of the reference run at its own start time; over [start, start + WINDOW] it
and the reference are two continuations of one state, and the difference of their window means is one
paired sample. The R paired differences are combined as replicas are (uncertainty.replica_means:
Student's t with R - 1 degrees of freedom, never narrower than the windows' own fluctuation allows).

    LC_ALL=C.UTF-8 .venv/bin/python studies/paper-400um/paired.py REFERENCE WINDOW RUN...

Per key quantity (mass flow at the sensors and through the domain, per-element solid fraction, axial
velocity and speed): the reference's mean over the R windows, the run's mean paired difference +- its 95 %
half-width (both relative to the reference), "differs" when that interval excludes zero, the bound
|difference| + half-width (the setting is within a tolerance when the bound is), and the
largest 95 % half-width of a single window (how well one window resolves the quantity on its own).
"""
from __future__ import annotations

import math
import sys

import numpy as np

from tsg_analysis.run import Run
from tsg_analysis.uncertainty import Estimate, replica_means


def start_time(run: Run) -> float:
    """The time the run continues its state from: its t_startup (a run from a state starts there)."""
    value = run.parameters.variables.get("t_startup")
    if value is None:
        raise SystemExit(f"{run.path}: no t_startup in its parameters: not a run continued from a state")
    return float(value)


def estimates(run: Run, start: float, end: float) -> dict[tuple[str, str], Estimate]:
    found = {(str(k[0]), str(k[1])): e for k, e in run.key_estimates(start, end).items()}
    found.update({("mass flow (kg/h)", name): e for name, e in run.sensor_flows(start, end).items()})
    return found


def pair_difference(reference: Estimate, run: Estimate) -> Estimate:
    """run - reference over one state's window, with both windows' standard errors (an upper bound for
    two continuations of one state, which are positively correlated)."""
    return Estimate(run.mean - reference.mean, math.hypot(reference.standard_error, run.standard_error),
                    reference.samples + run.samples, min(reference.independent_samples, run.independent_samples), math.nan)


def main(reference_dir: str, window: str, run_dirs: list[str]) -> None:
    if len(run_dirs) < 2:
        raise SystemExit("give at least 2 runs (states): a paired interval needs 2 pairs or more")
    length = float(window)
    reference = Run(reference_dir)
    pairs = []
    for path in run_dirs:
        run = Run(path)
        start = start_time(run)
        pairs.append((start, estimates(reference, start, start + length), estimates(run, start, start + length)))
    count = len(pairs)
    print(f"{' + '.join(str(p) for p in run_dirs)} against {reference_dir}: {count} states "
          f"({', '.join(f'{s:.4f}' for s, _, _ in pairs)} s), {length:g} s each; 95 % half-widths relative to the "
          f"reference's mean, the differences combined as replica means ({count - 1} degrees of freedom)")
    print("| quantity | scope | reference | run - reference | differs | bound | per-pair differences | one window's half-width |")
    print("|---|---|---|---|---|---|---|---|")
    keys = [k for k in pairs[0][1] if all(k in r and k in p for _, r, p in pairs)]
    for key in keys:
        ref = np.array([r[key].mean for _, r, _ in pairs])
        differences = [pair_difference(r[key], p[key]) for _, r, p in pairs]
        diff = np.array([d.mean for d in differences])
        scale = abs(float(ref.mean()))
        if not scale > 0 or not np.all(np.isfinite(diff)):
            continue
        combined = replica_means(differences)
        mean, half = combined.mean, combined.half_width
        single = max(e[key].half_width for _, r, p in pairs for e in (r, p))
        per_pair = ", ".join(f"{d / scale:+.1%}" for d in diff)
        print(f"| {key[0]} | {key[1]} | {ref.mean():.4g} | {mean / scale:+.1%} ± {half / scale:.1%} | "
              f"{'yes' if abs(mean) > half else 'no'} | {(abs(mean) + half) / scale:.1%} | {per_pair} | {single / scale:.1%} |")


if __name__ == "__main__":
    if len(sys.argv) < 4:
        raise SystemExit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3:])
