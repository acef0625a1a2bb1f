"""Command line:

    python -m tsg_analysis report <run_dir> [<run_dir> ...] --out <dir>   report.md, figures, JSON, CSV
    python -m tsg_analysis summary <run_dir> [<run_dir> ...]                 the run's summary table (replicas combined)
    python -m tsg_analysis compare <reference_dir> <run_dir> [...]          differences ± 95 % interval
                                   (replicas of one setting comma-separated: a,b,c)
    python -m tsg_analysis domains <full_run> --periodic-zones ZONES        hold-up of the periodic elements
    python -m tsg_analysis domains <full_run> --periodic a,b,c --out DIR    periodic against full (Figs. 8-9)

A user mistake gives one line naming the option, the value and what is allowed, and exit status 2
(an unusable input file: exit status 1); --debug shows the traceback instead.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import NoReturn

from .cross_section import BORE_RADIUS, DEFAULT_BIN_SIZE
from .massflow import STEADY_TOLERANCE
from .run import Run
from .run_files import AnalysisInputError

USAGE_ERROR = 2
INPUT_ERROR = 1


class UsageError(Exception):
    """A command-line value that is not allowed (one line, names the option)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line instead of usage + message
        raise UsageError(f"{self.prog}: {message} (see --help)")


def _bounded(option: str, value: float | None, what: str, low: float, high: float = math.inf,
             low_inclusive: bool = False) -> None:
    if value is None:
        return
    above = value >= low if low_inclusive else value > low
    if not (math.isfinite(value) and above and value <= high):
        raise UsageError(f"{option} {value:g} is not allowed: {what}")


def _check_report_arguments(args: argparse.Namespace) -> list[str] | None:
    _bounded("--steady-window", args.steady_window, "seconds per steady-state window, a finite number > 0", 0.0)
    _bounded("--steady-tolerance", args.steady_tolerance,
             "relative inlet/outlet difference, a number with 0 < tolerance < 1", 0.0, 1.0 - 1e-12)
    _bounded("--bin-size", args.bin_size, f"cross-section bin size in m, 0 < size <= {BORE_RADIUS:g} (the bore "
             "radius)", 0.0, BORE_RADIUS)
    _bounded("--density", args.density, "particle density in kg/m^3, a finite number > 0", 0.0)
    for run_dir in args.run_dirs:
        if not run_dir.exists():
            raise UsageError(f"run_dir {run_dir}: no such directory")
        if not run_dir.is_dir():
            raise UsageError(f"run_dir {run_dir}: is a file, not a run directory")
    if args.out.exists() and not args.out.is_dir():
        raise UsageError(f"--out {args.out}: is an existing file; give a directory (created if missing)")
    if any(args.out.resolve() == run_dir.resolve() for run_dir in args.run_dirs):
        raise UsageError(f"--out {args.out}: is a run directory; give a separate directory for the report")
    if args.labels is None:
        return None
    labels = args.labels.split(",")
    if len(labels) != len(args.run_dirs):
        raise UsageError(f"--labels {args.labels!r}: {len(labels)} labels for {len(args.run_dirs)} run directories; "
                         "give one per run directory, comma-separated")
    if any(not label.strip() for label in labels) or len(set(labels)) != len(labels):
        raise UsageError(f"--labels {args.labels!r}: labels must be non-empty and distinct")
    return labels


def _report(args: argparse.Namespace) -> int:
    labels = _check_report_arguments(args)
    if args.allow_transient and args.require_steady:
        raise UsageError("--allow-transient and --require-steady contradict each other; give at most one")
    try:
        args.out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise UsageError(f"--out {args.out}: cannot create the directory ({err.strerror})") from None
    from .model import Settings  # heavy imports (matplotlib, pymbar) only once the arguments are good
    from .report import build_report
    settings = Settings(steady_window=args.steady_window, steady_tolerance=args.steady_tolerance,
                        require_steady=args.require_steady, bin_size=args.bin_size,
                        particle_density=args.density, snapshot=not args.no_snapshot)
    result = build_report(args.run_dirs, args.out, labels, settings)
    for run in result.runs:
        steady = run.steady.message if run.steady is not None else "steady state unknown"
        print(f"[{run.label}] {steady}")
    for run_label, part, reason in result.not_produced:
        print(f"[{run_label}] not produced: {part}: {reason}", file=sys.stderr)
    print(f"report: {args.out / 'report.md'}")
    return 0


def _summary(args: argparse.Namespace) -> int:
    from .summary import summary_table

    for run_dir in args.run_dirs:
        if not run_dir.is_dir():
            raise UsageError(f"run_dir {run_dir}: no such directory")
    print(summary_table([Run(run_dir) for run_dir in args.run_dirs]))
    return 0


def _replicas(argument: str) -> list[Run]:
    """'a,b,c': replica runs (differing only in the seed) combined into one entry."""
    run_dirs = [Path(part) for part in argument.split(",") if part]
    for run_dir in run_dirs or [Path(argument)]:
        if not run_dir.is_dir():
            raise UsageError(f"run_dir {run_dir}: no such directory")
    return [Run(run_dir) for run_dir in run_dirs]


def _compare(args: argparse.Namespace) -> int:
    from .summary import compare_runs, sweep_markdown, write_sweep_csv

    reference = _replicas(args.reference)
    variants = {argument: _replicas(argument) for argument in args.run_dirs}
    if args.csv is not None and args.csv.is_dir():
        raise UsageError(f"--csv {args.csv}: is a directory; give a file name")
    every = reference + [run for runs in variants.values() for run in runs]
    start = None if args.start is None else max(_start("--start", args.start, run) for run in every)
    end = None if args.end is None else _time("--end", args.end)
    if start is not None and end is not None and end <= start:
        raise UsageError(f"--end {args.end}: must be later than the window's start, {start:.4g} s")
    if start is not None or end is not None:
        print("every run" + ("" if start is None else f" from t = {start:.4g} s")
              + (" (the latest detected steady start)" if args.start == "auto" else "")
              + ("" if end is None else f" up to t = {end:.4g} s"))
    rows = compare_runs(reference, variants, start, end)
    print(sweep_markdown(rows), end="")
    if args.csv is not None:
        write_sweep_csv(rows, args.csv)
    return 0


def _start(option: str, text: str, run: Run) -> float:
    """--*-start: a time in s >= 0, or 'auto' (the run's detected steady start)."""
    from .validation import steady_start

    if text == "auto":
        found = steady_start(run)
        if found is None:
            raise UsageError(f"{option} auto: {run.path} has too short a record to detect a steady state; give a time")
        return found
    return _time(option, text, "a time in s >= 0, or 'auto'")


def _time(option: str, text: str, allowed: str = "a time in s >= 0") -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not value >= 0.0:
        raise UsageError(f"{option} {text} is not allowed: {allowed}")
    return value


def _domains(args: argparse.Namespace) -> int:
    from .domains import TIME_BY_BALANCE, UNITS, compare_domains, domains_markdown, full_steady_start, machine_residence, section_holdup
    from .figures import plot_domain_elements, plot_rtd_comparison
    from .model import AXIAL_VELOCITY, SOLID_FRACTION, SPEED
    from .run_files import mesh_zones

    if not args.full_run.is_dir():
        raise UsageError(f"full_run {args.full_run}: no such directory")
    if args.periodic is None and args.periodic_zones is None:
        raise UsageError("domains: give --periodic a,b,c (runs to compare) or --periodic-zones FILE (the hold-up only)")
    full_run = Run(args.full_run)
    periodic = _replicas(args.periodic) if args.periodic is not None else []
    section = mesh_zones(args.periodic_zones) if args.periodic is None else periodic[0].zones  # a mesh directory, not a run
    # the full run fills from empty: its steady start is found on the section's hold-up and flux
    full_start = (full_steady_start(full_run, section) if args.full_start == "auto"
                  else _start("--full-start", args.full_start, full_run))
    if args.periodic is None:
        holdup = section_holdup(full_run, section, full_start)
        print(f"hold-up on the periodic domain's elements from t = {full_start:.4g} s: {holdup.mean * 1e3:.4g} g "
              f"(in kg: {holdup.text('kg')})")
        print(machine_residence(full_run, full_start).text())
        return 0
    if args.out is None:
        raise UsageError("domains --periodic: give --out DIR for the table and the figure")
    starts = [_start("--periodic-start", args.periodic_start, d) for d in periodic]
    comparison = compare_domains(full_run, periodic, full_start, max(starts))
    args.out.mkdir(parents=True, exist_ok=True)
    header = (f"Periodic {', '.join(str(run.path) for run in periodic)} (from t = {max(starts):.4g} s) against full "
              f"{args.full_run} (from t = {full_start:.4g} s).\n\n")
    text = header + domains_markdown(comparison)
    (args.out / "domains.md").write_text(text, encoding="utf-8")
    plot_rtd_comparison(args.out / "rtd.png", [(label, samples) for label, samples in comparison.samples.items()],
                        {("periodic", c.scope): c for c in comparison.rtds})
    plot_domain_elements(args.out / "elements.png", comparison.rows, (SOLID_FRACTION, SPEED, AXIAL_VELOCITY, TIME_BY_BALANCE),
                         UNITS)
    print(text + f"\nwritten: {args.out}/domains.md, rtd.png, elements.png")
    return 0


def _systematics(args: argparse.Namespace) -> int:
    from . import systematics

    if not args.study_dir.is_dir():
        raise UsageError(f"study_dir {args.study_dir}: no such directory")
    entries = systematics.from_accuracy(args.study_dir, args.name, args.window, args.where)
    systematics.add(entries)
    print(f"{systematics.REGISTRY}: study {args.name}, {len(entries)} entries")
    for e in entries:
        print(f"  {e.setting} {e.value} against {e.reference}: {e.text()}")
    return 0


def _merge_elements(args: argparse.Namespace) -> int:
    from .run_files import element_segment_files, merged_element_text

    if not args.run_dir.is_dir():
        raise UsageError(f"run_dir {args.run_dir}: no such directory")
    segments = element_segment_files(args.run_dir)
    earlier = [p for p in segments if p.name != "elements.txt"]
    if not earlier:
        print(f"{args.run_dir}: one segment, elements.txt left as it is")
        return 0
    text, _ = merged_element_text(segments)
    merged = args.run_dir / "elements.merged"
    merged.write_text(text)
    merged.replace(args.run_dir / "elements.txt")
    for path in earlier:
        path.unlink()
    print(f"{args.run_dir}/elements.txt: {len(segments)} segments merged")
    return 0


def parser() -> argparse.ArgumentParser:
    main_parser = _Parser(prog="python -m tsg_analysis", description="Post-analysis of TSG-DEM runs.")
    main_parser.add_argument("--debug", action="store_true", help="show the Python traceback of an error")
    commands = main_parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    report = commands.add_parser(
        "report", help="write report.md, PNG figures, summary.json and CSV tables for one or several runs",
        description="Analyse run directories (params.json, log.lammps, zones.txt, residence.txt, elements.txt, "
                    "massflow.txt, optional dumps/ and meshes/); several runs are compared against the first.")
    report.add_argument("run_dirs", nargs="+", type=Path, metavar="run_dir")
    report.add_argument("--out", required=True, type=Path, help="output directory (created)")
    report.add_argument("--labels", help="comma-separated run labels (default: directory names)")
    report.add_argument("--steady-window", type=float,
                        help="seconds per steady-state window (default: one screw revolution at the run's rpm)")
    report.add_argument("--steady-tolerance", type=float, default=STEADY_TOLERANCE,
                        help="allowed relative inlet/outlet difference (default %(default)s)")
    report.add_argument("--require-steady", action="store_true",
                        help="produce no time averages for a run that is not steady (default: average the whole "
                             "record and mark it transient)")
    # the default since transient runs are averaged and flagged; accepted for tests/cases/test_cases_smoke.py,
    # which passes it (to be dropped once that caller is updated)
    report.add_argument("--allow-transient", action="store_true", help=argparse.SUPPRESS)
    report.add_argument("--bin-size", type=float, default=DEFAULT_BIN_SIZE,
                        help="cross-section bin size in m (default %(default)s)")
    report.add_argument("--density", type=float,
                        help="particle density (kg/m^3) for dumps without a mass column (default: the run's rho_p)")
    report.add_argument("--no-snapshot", action="store_true", help="skip the pyvista snapshot")
    report.add_argument("--debug", action="store_true", help=argparse.SUPPRESS)
    summary = commands.add_parser("summary", help="print a run's summary: every quantity ± 95 %% interval; several "
                                  "runs: replicas (fill seeds) combined")
    summary.add_argument("run_dirs", type=Path, nargs="+", metavar="run_dir")
    summary.add_argument("--debug", action="store_true", help=argparse.SUPPRESS)
    compare = commands.add_parser("compare", help="differences of runs against a reference ± 95 %% interval")
    compare.add_argument("reference", help="reference run directory; replicas comma-separated (a,b,c)")
    compare.add_argument("run_dirs", nargs="+", metavar="run_dir",
                         help="run directories to compare; replicas of one variant comma-separated")
    compare.add_argument("--csv", type=Path, help="also write the table as CSV")
    compare.add_argument("--start", help="analyse every run from this time on, s, or 'auto': the latest of the runs' "
                                         "detected steady starts (default: the whole sampling record)")
    compare.add_argument("--end", help="analyse every run up to this time, s (default: the end of each record), "
                                       "so that runs of different lengths are compared over the same window")
    compare.add_argument("--debug", action="store_true", help=argparse.SUPPRESS)
    domains = commands.add_parser("domains", help="the periodic sub-domain against the full granulator")
    domains.add_argument("full_run", type=Path)
    domains.add_argument("--periodic", help="periodic run directories, replicas comma-separated (a,b,c)")
    domains.add_argument("--periodic-zones", type=Path, help="the periodic domain's mesh directory or its zones.txt (hold-up only)")
    domains.add_argument("--out", type=Path, help="output directory for domains.md, rtd.png and elements.png")
    domains.add_argument("--full-start", default="auto",
                         help="steady start of the full run, s, or auto: the later of the starts of stationarity of the "
                              "hold-up and the flux on the periodic domain's section, refused when fewer than 20 "
                              "independent samples of the hold-up follow")
    domains.add_argument("--periodic-start", default="auto", help="steady start of the periodic runs, s, or auto")
    domains.add_argument("--debug", action="store_true", help=argparse.SUPPRESS)
    merge = commands.add_parser(
        "merge-elements", help="a stopped or finished segmented run's element statistics in one elements.txt",
        description="Writes the run's elements.upto-*.txt and elements.txt (cases/slurm/segment.sh) as one "
                    "elements.txt, each sampled step once (the later segment's rows win), and removes the "
                    "elements.upto-*.txt. Only for a run no segment is writing: the other commands read the "
                    "segments as they are.")
    merge.add_argument("run_dir", type=Path)
    merge.add_argument("--debug", action="store_true", help=argparse.SUPPRESS)
    systematics = commands.add_parser("systematics", help="add an accuracy study's measured errors to the registry "
                                      "that the summary and the report quote (tsg_analysis/systematics.json)")
    systematics.add_argument("action", choices=("add",))
    systematics.add_argument("study_dir", type=Path, help="a tsg-accuracy study directory (its accuracy.json)")
    systematics.add_argument("--name", required=True, help="the study's name in the registry (replaces one of that name)")
    systematics.add_argument("--window", required=True, help="how its runs were sampled, in words (quoted beside its numbers)")
    systematics.add_argument("--where", help="the folder its outputs are kept in (default: study_dir)")
    systematics.add_argument("--debug", action="store_true", help=argparse.SUPPRESS)
    return main_parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    debug = "--debug" in argv
    try:
        args = parser().parse_args(argv)
        return {"report": _report, "summary": _summary, "compare": _compare, "domains": _domains,
                "systematics": _systematics, "merge-elements": _merge_elements}[args.command](args)
    except UsageError as err:
        if debug:
            raise
        print(f"error: {err}", file=sys.stderr)
        return USAGE_ERROR
    except AnalysisInputError as err:
        if debug:
            raise
        print(f"error: {err}", file=sys.stderr)
        return INPUT_ERROR
    except OSError as err:  # e.g. an output directory that is not writable
        if debug:
            raise
        print(f"error: {err.filename or ''}: {err.strerror or err}", file=sys.stderr)
        return INPUT_ERROR


if __name__ == "__main__":
    sys.exit(main())
