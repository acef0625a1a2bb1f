"""The particle-size ladder at steady state: each size against the next finer one (issue 18, item 1).

    .venv/bin/python studies/validation/size-ladder.py START|auto SIZE=RUN,RUN,... [SIZE=RUN,...] [--out FILE.md]

SIZE is a label (e.g. 0.6mm), listed from the finest to the coarsest; the runs of a size are its
replicas (fill seeds). Every run is analysed from START s on (auto: the latest detected start of
stationarity of the domain flux over all the runs, tsg_analysis.validation.steady_start). Prints (and writes with --out) two
Markdown tables:
- per size: the domain flux and, per element, the solid fraction and axial velocity, each replicas
  combined ± 95 % (tsg_analysis.summary.combined_rows);
- per neighbouring pair: the coarser size minus the finer one, per quantity and element
  (tsg_analysis.summary.compare_runs): how many element differences are significant and the
  largest relative one. A size whose differences from the next finer one are all within their
  intervals is on the plateau (the paper's critical ratio: results that no longer depend on size).
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from tsg_analysis.model import AXIAL_VELOCITY, DOMAIN_FLUX, MASS_FLOW, SOLID_FRACTION
from tsg_analysis.run import Run
from tsg_analysis.summary import combined_rows, compare_runs
from tsg_analysis.uncertainty import format_interval
from tsg_analysis.validation import steady_start

QUANTITIES = (SOLID_FRACTION, AXIAL_VELOCITY)


def parse_size(text: str) -> tuple[str, list[Run]]:
    label, _, runs = text.partition("=")
    paths = [Path(p) for p in runs.split(",") if p]
    if not label or not paths:
        raise SystemExit(f"{text}: give SIZE=RUN,RUN,...")
    for path in paths:
        if not path.is_dir():
            raise SystemExit(f"{path}: no such run directory")
    return label, [Run(path) for path in paths]


def element_scopes(rows: dict) -> list[str]:
    return [scope for quantity, scope in rows if quantity == SOLID_FRACTION]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("start")
    parser.add_argument("sizes", nargs="+", type=parse_size)
    parser.add_argument("--out", type=Path)
    args = parser.parse_args(argv)
    sizes: list[tuple[str, list[Run]]] = args.sizes
    if args.start == "auto":
        starts = [steady_start(run) for _, runs in sizes for run in runs]
        if any(start is None for start in starts):
            raise SystemExit("auto: a run's record is too short to detect its steady start; give START in s")
        args.start = max(s for s in starts if s is not None)
    else:
        args.start = float(args.start)
    combined = {label: combined_rows(runs, args.start) for label, runs in sizes}
    scopes = element_scopes(combined[sizes[0][0]])

    def cell(estimate) -> str:   # mean ± 95 %; "*" where the interval is only indicative
        text = format_interval(estimate.mean, estimate.half_width)
        return text if estimate.resolved else text + " *"

    lines = [f"Every run from t = {args.start:.4g} s; replicas combined, ± 95 % (* indicative: too few replicas "
             "or independent samples).", ""]
    for title, quantity in (("domain flux (kg/h)", None), *((q, q) for q in QUANTITIES)):
        columns = ["domain"] if quantity is None else scopes
        lines += [f"{title}:", "", "| size | fills | " + " | ".join(columns) + " |", "|---|---|" + "---|" * len(columns)]
        for label, runs in sizes:
            rows = combined[label]
            cells = [cell(rows[(MASS_FLOW, DOMAIN_FLUX)])] if quantity is None else \
                [cell(rows[(quantity, scope)]) for scope in scopes]
            lines.append(f"| {label} | {len(runs)} | " + " | ".join(cells) + " |")
        lines.append("")

    lines += ["| coarser − finer | domain flux | " + " | ".join(
        f"{q}: significant, largest" for q in QUANTITIES) + " |", "|---|---|" + "---|" * len(QUANTITIES)]
    for (fine, fine_runs), (coarse, coarse_runs) in zip(sizes, sizes[1:]):
        rows = compare_runs(fine_runs, {coarse: coarse_runs}, args.start)
        flux = next(r for r in rows if r.quantity == MASS_FLOW and r.scope == DOMAIN_FLUX)
        cells = [flux.difference.text("kg/h")]
        for quantity in QUANTITIES:
            element_rows = [r for r in rows if r.quantity == quantity and r.scope in scopes]
            significant = [r for r in element_rows if r.difference.significant]
            largest = max(element_rows, key=lambda r: abs(r.difference.relative) if math.isfinite(
                r.difference.relative) else 0.0)
            cells.append(f"{len(significant)} of {len(element_rows)}; {largest.scope} "
                         f"{format_interval(largest.difference.value, largest.difference.half_width, signed=True)} "
                         f"({largest.difference.relative:+.0%})")
        lines.append(f"| {coarse} − {fine} | " + " | ".join(cells) + " |")
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if args.out:
        args.out.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
