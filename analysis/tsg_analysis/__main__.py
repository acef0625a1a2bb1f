"""Command line: python -m tsg_analysis report <run_dir> [<run_dir> ...] --out <dir>"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .cross_section import DEFAULT_BIN_SIZE
from .massflow import STEADY_TOLERANCE, STEADY_WINDOW_S
from .report import Settings, build_report


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tsg_analysis", description="Post-analysis of TSG-DEM runs.")
    commands = parser.add_subparsers(dest="command", required=True)
    report = commands.add_parser(
        "report", help="write report.md, PNG figures, summary.json and CSV tables for one or several runs",
        description="Analyse run directories (log.lammps, zones.txt, residence.txt, elements.txt, massflow.txt, "
                    "optional dumps/ and meshes/); several runs are compared against the first.")
    report.add_argument("run_dirs", nargs="+", type=Path, metavar="run_dir")
    report.add_argument("--out", required=True, type=Path, help="output directory (created)")
    report.add_argument("--labels", help="comma-separated run labels (default: directory names)")
    report.add_argument("--steady-window", type=float, default=STEADY_WINDOW_S,
                        help="seconds per mass-flow averaging window (default %(default)s)")
    report.add_argument("--steady-tolerance", type=float, default=STEADY_TOLERANCE,
                        help="allowed relative inlet/outlet difference (default %(default)s)")
    report.add_argument("--allow-transient", action="store_true",
                        help="average over the whole record when a run is not (known to be) steady")
    report.add_argument("--bin-size", type=float, default=DEFAULT_BIN_SIZE,
                        help="cross-section bin size in m (default %(default)s)")
    report.add_argument("--screw-rpm", type=float, default=600.0,
                        help="screw speed used to turn the meshes in the snapshot; 0: draw them as built")
    report.add_argument("--density", type=float, help="particle density (kg/m^3) for dumps without a mass column")
    report.add_argument("--no-snapshot", action="store_true", help="skip the pyvista snapshot")
    args = parser.parse_args(argv)

    labels = args.labels.split(",") if args.labels else None
    if labels is not None and len(labels) != len(args.run_dirs):
        parser.error(f"--labels has {len(labels)} labels for {len(args.run_dirs)} run directories")
    settings = Settings(steady_window=args.steady_window, steady_tolerance=args.steady_tolerance,
                        allow_transient=args.allow_transient, bin_size=args.bin_size,
                        screw_rpm=args.screw_rpm or None, particle_density=args.density,
                        snapshot=not args.no_snapshot)
    result = build_report(args.run_dirs, args.out, labels, settings)
    for run in result.runs:
        steady = run.steady.message if run.steady is not None else "steady state unknown"
        print(f"[{run.label}] {steady}")
    for run_label, part, reason in result.not_produced:
        print(f"[{run_label}] not produced: {part}: {reason}", file=sys.stderr)
    print(f"report: {args.out / 'report.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
