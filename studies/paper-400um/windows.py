"""One run's key numbers over consecutive windows, and each window against the first: the drift check
of a long run (is the sampling window steady?), ± 95 %.

    .venv/bin/python studies/paper-400um/windows.py runs/paper-400um-faithful 0.5 0.767 0.93
"""
from __future__ import annotations

import argparse

from tsg_analysis.run import Run
from tsg_analysis.summary import MASS_FLOW, UNITS
from tsg_analysis.uncertainty import difference


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("run_dir")
    parser.add_argument("edges", nargs="+", type=float, help="window edges, s (at least two, increasing)")
    args = parser.parse_args()
    if len(args.edges) < 2 or any(b <= a for a, b in zip(args.edges, args.edges[1:])):
        parser.error(f"edges {args.edges}: give at least two increasing times in s")
    run = Run(args.run_dir)
    windows = list(zip(args.edges, args.edges[1:]))
    estimates = []
    for start, end in windows:
        found = {(MASS_FLOW, name): e for name, e in run.sensor_flows(start, end).items()}
        found.update(run.element_keys(start, end))
        estimates.append(found)
    titles = [f"{a:g}–{b:g} s" for a, b in windows]
    print("| quantity | scope | " + " | ".join(titles) + " | " + " | ".join(f"{t} − first" for t in titles[1:]) + " |")
    print("|---|---|" + "---|" * (2 * len(windows) - 1))
    for key in estimates[0]:
        quantity, scope = key
        if quantity not in UNITS or not all(key in e for e in estimates):
            continue
        first = estimates[0][key]
        changes = [difference(first, e[key]).text(UNITS[quantity]) for e in estimates[1:]]
        print(f"| {quantity} ({UNITS[quantity]}) | {scope} | " + " | ".join(e[key].text() for e in estimates)
              + " | " + " | ".join(changes) + " |")


if __name__ == "__main__":
    main()
