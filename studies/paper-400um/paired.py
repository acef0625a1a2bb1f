"""A setting against the reference, paired by state (treatment-2.7g/, dt-paired-2.7g/). Each run of the
setting continues a state of the reference run at its own start time; over [start, start + WINDOW] it
and the reference are two continuations of one state, compared sample by sample
(tsg_analysis.paired: the difference series, whose interval leaves out what both runs share — the state
they start from and the screws' phase). The R states' differences are combined as replicas are
(uncertainty.replica_means: Student's t with R - 1 degrees of freedom, never narrower than the
difference series' own fluctuation allows).

    LC_ALL=C.UTF-8 .venv/bin/python studies/paper-400um/paired.py REFERENCE WINDOW RUN...

Per key quantity (mass flow at the sensors and through the domain, per-element solid fraction, axial
velocity and speed): the reference's mean over the R windows, the run's mean paired difference +- its 95 %
half-width (both relative to the reference), "differs" when that interval excludes zero, the bound
|difference| + half-width (the setting is within a tolerance when the bound is), the per-state
differences, the largest 95 % half-width of one state's difference series, the largest of a single
window (how well one window resolves the quantity on its own, unpaired), and the mean difference over
the window's second half alone (the difference series starts at zero, the two runs sharing their
state: an effect that is still growing within the window shows there larger than over the whole
window, which then understates where the difference is going).
"""
from __future__ import annotations

import sys

import numpy as np

from tsg_analysis.model import MASS_FLOW
from tsg_analysis.paired import paired_differences
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
    found.update({(MASS_FLOW, name): e for name, e in run.sensor_flows(start, end).items()})
    return found


def main(reference_dir: str, window: str, run_dirs: list[str]) -> None:
    if len(run_dirs) < 2:
        raise SystemExit("give at least 2 runs (states): a paired interval needs 2 pairs or more")
    length = float(window)
    reference = Run(reference_dir)
    pairs = []
    for path in run_dirs:
        run = Run(path)
        start = start_time(run)
        end = start + length
        pairs.append((start, estimates(reference, start, end), estimates(run, start, end),
                      paired_differences(reference, run, start, end)))
    count = len(pairs)
    later_halves = [(start, paired_differences(reference, Run(path), start + length / 2, start + length))
                    for path, (start, *_) in zip(run_dirs, pairs)]
    print(f"{' + '.join(str(p) for p in run_dirs)} against {reference_dir}: {count} states "
          f"({', '.join(f'{s:.4f}' for s, *_ in pairs)} s), {length:g} s each; 95 % half-widths relative to the "
          f"reference's mean, the differences combined as replica means ({count - 1} degrees of freedom)")
    print("| quantity | scope | reference | run - reference | differs | bound | per-state differences | "
          "one state's paired half-width | one window's half-width | second half: run - reference |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    keys = [k for k in pairs[0][1] if all(k in r and k in p and k in d for _, r, p, d in pairs)]
    for key in keys:
        ref = np.array([r[key].mean for _, r, _, _ in pairs])
        differences = [d[key] for *_, d in pairs]
        diff = np.array([d.mean for d in differences])
        scale = abs(float(ref.mean()))
        if not scale > 0 or not np.all(np.isfinite(diff)):
            continue
        combined = replica_means(differences)
        mean, half = combined.mean, combined.half_width
        single = max(e[key].half_width for _, r, p, _ in pairs for e in (r, p))
        paired_single = max(d.half_width for d in differences)
        later = float(np.mean([d[key].mean for *_, d in later_halves]))
        per_pair = ", ".join(f"{d / scale:+.1%}" for d in diff)
        print(f"| {key[0]} | {key[1]} | {ref.mean():.4g} | {mean / scale:+.1%} ± {half / scale:.1%} | "
              f"{'yes' if abs(mean) > half else 'no'} | {(abs(mean) + half) / scale:.1%} | {per_pair} | "
              f"{paired_single / scale:.1%} | {single / scale:.1%} | {later / scale:+.1%} |")


if __name__ == "__main__":
    if len(sys.argv) < 4:
        raise SystemExit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3:])
