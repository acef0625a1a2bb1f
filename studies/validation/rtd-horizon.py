"""How the Fig. 8 comparison (tsg_analysis domains) depends on where the periodic passes start counting.

    .venv/bin/python studies/validation/rtd-horizon.py FULL_RUN PERIODIC_RUN FULL_START PERIODIC_START H [H ...]

The full run's passes of the section are those `domains` uses (outlet records and the inside
snapshot, from FULL_START + RECORD_HORIZON balance times of the section on). The periodic run's count
from H balance times of its section after its first recorded entry, for each H given (`domains` uses
RECORD_HORIZON = 3). Prints, per H and scope, the pass counts, the mean times, the KS distance and the
KS test's p-value. Used for docs/validation.md.
"""
from __future__ import annotations

import sys

import numpy as np

from tsg_analysis.domains import RECORD_HORIZON, balance_passage, counted_lengths, full_passes, passage_times, section_indices
from tsg_analysis.rtd import compare_rtds
from tsg_analysis.run import Run


def main(full_run: Run, periodic_run: Run, full_start: float, periodic_start: float, horizons: list[float]) -> None:
    periodic, full = periodic_run.zones, full_run.zones
    index = section_indices(full, periodic)
    full_length = (full.x_end - full.x_start)[index]
    periodic_length = periodic.x_end - periodic.x_start
    section = float(periodic_length.sum())
    full_after = full_start + RECORD_HORIZON * balance_passage(full_run, index, periodic_length / full_length,
                                                               section, full_start).mean
    passes = full_passes(full_run, max(index), full_after)
    record_share = counted_lengths(periodic, [periodic_run]) / full_length
    periodic_balance = balance_passage(periodic_run, range(len(periodic)), np.ones(len(periodic)), section,
                                       periodic_start).mean
    scopes = {"conveying elements": [j for j, k in enumerate(periodic.kind) if k == "conveying"],
              "kneading block": [j for j, k in enumerate(periodic.kind) if k == "kneading"],
              "section": list(range(len(periodic)))}
    print(f"full: {len(passes.exit_time)} passes ending in ({full_after:.4g}, {passes.snapshot:.4g}] s")
    print("| H | periodic passes from (s) | scope | full mean (s) | periodic passes | periodic mean (s) | KS D | p-value |")
    print("|---|---|---|---|---|---|---|---|")
    for horizon in horizons:
        for scope, zones in scopes.items():
            full_times = passes.time_by_zone[:, [index[j] for j in zones]] @ record_share[zones]
            periodic_times = passage_times(periodic_run, zones, periodic_start, horizon=horizon * periodic_balance)
            if len(periodic_times) < 2:
                print(f"| {horizon:g} | {horizon * periodic_balance:.3g} | {scope} | {full_times.mean():.3f} | "
                      f"{len(periodic_times)} | - | - | - |")
                continue
            c = compare_rtds(full_times, periodic_times, scope)
            print(f"| {horizon:g} | {horizon * periodic_balance:.3g} | {scope} | {full_times.mean():.3f} | "
                  f"{len(periodic_times)} | {periodic_times.mean():.3f} | {c.ks_distance:.3f} | {c.ks_p_value:.2g} |")


if __name__ == "__main__":
    if len(sys.argv) < 6:
        sys.exit(__doc__)
    main(Run(sys.argv[1]), Run(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), [float(h) for h in sys.argv[5:]])
