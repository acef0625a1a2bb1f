"""Sensitivity matrix of the seed paper as run directories: write, run (resumable), status.

    tsg-sweep write SWEEP_DIR [--scale paper|demo] [--np N] [--replicas R | --seeds K ...] [--only NAME ...] [-v name value ...]
    tsg-sweep run SWEEP_DIR [--only NAME ...]      # locally, one after the other
    tsg-sweep status SWEEP_DIR
    tsg-sweep report SWEEP_DIR [--out DIR] [--start T|auto] [--parts K]   # differences ± 95 %, the paper's directions
    sbatch SWEEP_DIR/sweep.slurm                               # on a cluster: one array task per run

The matrix (periodic case): the Table 3 reference; Table 4's univariate variations (restitution
0.1 and 0.9, static friction 0.1, rolling friction 0.2, relative standard deviation 0.2, high
cohesion), each applied to particle–particle and particle–geometry alike as the paper does; and
the particle-size series of Section 2.4 (mean diameter 200–1500 um, same mass). Overrides (-v) are
checked against the periodic case's variables and value rules when written. With --replicas R each
setting is R runs that differ only in the fill seed (tsg-run-case --seed 1 … R), in NAME/seed-K:
their window means give intervals that hold for windows too short for a time-series interval
(docs/statistics.md); --seeds K ... names the seeds instead. Writing into an existing sweep directory adds runs
to it (runs.txt keeps the runs it lists): e.g. a fourth seed for a setting whose run the guards stopped,
`--only NAME --seeds 4` with the same options. A run that exists already must be written with what it was
written with. --only writes a part of the matrix (e.g. no 200 um run at demo scale). Each
run directory
holds `sweep.json` (what the sweep sets), `run.sh` (the local command) and, once run, the case outputs and a state
marker: RUNNING (process id, host and SLURM job id), DONE or FAILED (with the exit status). A run that is
running (here, or on another host: a cluster node, which this host cannot check) is skipped by `run`. `report` compares each
setting's finished runs with the reference's (tsg_analysis.summary.compare_runs: replicas combined,
difference ± 95 % interval, significant or not) and sets the seed paper's directions and mass flows
beside ours (tsg_analysis.validation); it writes comparison.md/.csv, directions.md, splits.md (where the sweep holds
particle–particle-only and particle–geometry-only variations: the pair claims of Figs. 13–15), parts.md (the flux in each of K
consecutive parts of the window, default 2), mass-flow.png and elements.png (per-element panels). By default every
run is averaged over its whole sampling record; --start T from T s on, --start auto from the steady state detected
in the runs: the latest over the finished runs of the start of stationarity of the domain flux (pymbar's
equilibration detection, tsg_analysis.uncertainty.detect_start), one window for all. The runner's output, with its progress line every ~10 s
(cases/progress.py), goes to the terminal and to run.out.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shlex
import socket
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from tsg_cases.case_parameters import ParameterError, check_names, check_values, defined_variables

# The RUNNING marker: the run script's process id, its host and SLURM job id (empty outside SLURM).
RUNNING_MARK = 'echo "$$ $(hostname) ${SLURM_JOB_ID:-}" > "$here/RUNNING"'

ROOT = Path(__file__).resolve().parents[1]

if TYPE_CHECKING:
    from tsg_analysis.run import Run

BOTH = ("pp", "pg")   # Table 4: χ, μs and μr apply to both particle–particle and particle–geometry


def matrix() -> dict[str, dict[str, object]]:
    runs: dict[str, dict[str, object]] = {"reference": {}}
    for value in (0.1, 0.9):
        runs[f"restitution-{value}"] = {f"e_{k}": value for k in BOTH}
    runs["static-friction-0.1"] = {f"mus_{k}": 0.1 for k in BOTH}
    runs["rolling-friction-0.2"] = {f"mur_{k}": 0.2 for k in BOTH}
    runs["psd-sigma-0.2"] = {"psd_sigma": 0.2}
    runs["cohesion-high"] = {"cohesion": 1}
    for microns in (200, 600, 800, 1000, 1500):          # 400 um is the reference
        runs[f"diameter-{microns}um"] = {"d_mean": round(microns * 1e-6, 12)}
    return runs


def write(sweep: Path, scale: str, ranks: int, overrides: dict[str, str], replicas: int = 1,
          only: list[str] | None = None, seeds: list[int] | None = None) -> list[Path]:
    """Writes the runs (one per setting, or NAME/seed-K for each fill seed K: seeds 1 … replicas, or
    `seeds`) and adds them to the sweep's runs.txt, after the runs it lists already. A run directory
    that exists keeps its outputs only if what it would be written with is what it was written with."""
    check_names(overrides, "periodic")
    settings = matrix()
    unknown = sorted(set(only or ()) - set(settings))
    if unknown:
        raise ParameterError(f"--only {' '.join(unknown)} is not allowed: use names of the matrix ({', '.join(settings)})")
    if replicas < 1:
        raise ParameterError(f"--replicas {replicas} is not allowed: runs per setting that differ in the fill seed, >= 1")
    if seeds is not None:
        bad = [seed for seed in seeds if seed < 1]
        if bad or len(set(seeds)) != len(seeds) or not seeds:
            raise ParameterError(f"--seeds {' '.join(map(str, seeds))} is not allowed: distinct fill seeds >= 1")
    if only:
        settings = {name: variables for name, variables in settings.items() if name in only}
    for variables in settings.values():
        merged = {**{k: str(v) for k, v in variables.items()}, **overrides}
        check_values({**defined_variables("periodic"), **merged}, "periodic", overrides)
    if seeds is None and replicas > 1:
        seeds = list(range(1, replicas + 1))
    runs = [(name, variables, None) for name, variables in settings.items()] if seeds is None else \
        [(f"{name}/seed-{seed}", variables, seed) for name, variables in settings.items() for seed in seeds]
    listing = sweep / "runs.txt"
    listed = listing.read_text().split() if listing.is_file() else []
    for name, variables, seed in runs:
        described = {"case": "periodic", "scale": scale, "vars": {**{k: str(v) for k, v in variables.items()}, **overrides},
                     "seed": seed}
        setting = name.split("/")[0]
        if any(other.split("/")[0] == setting and (other == setting) != (seed is None) for other in listed):
            raise ParameterError(f"{sweep / name}: {sweep} already holds {setting} "
                                 f"{'with fill seeds (--replicas/--seeds)' if seed is None else 'without fill seeds'}; "
                                 "one setting's runs either all name their seed or none does")
        written = sweep / name / "sweep.json"
        if written.is_file() and json.loads(written.read_text()) != described:
            raise ParameterError(f"{sweep / name} was written with {written.read_text().strip()}, not "
                                 f"{json.dumps(described)}: its outputs belong to those settings; write to a new sweep directory")
    sweep.mkdir(parents=True, exist_ok=True)
    names = []
    for name, variables, seed in runs:
        run_dir = sweep / name
        run_dir.mkdir(parents=True, exist_ok=True)
        merged = {**{k: str(v) for k, v in variables.items()}, **overrides}
        (run_dir / "sweep.json").write_text(json.dumps({"case": "periodic", "scale": scale, "vars": merged,
                                                        "seed": seed}, indent=1))
        python = shlex.quote(sys.executable)
        seeding = f" --seed {seed}" if seed is not None else ""
        options = " ".join(f"-v {shlex.quote(k)} {shlex.quote(v)}" for k, v in merged.items())
        (run_dir / "run.sh").write_text(segmented_run_script(python, seeding, options, ranks) if scale == "paper" else
            "#!/usr/bin/env bash\n# One run of the sweep; its state goes to RUNNING / DONE / FAILED here.\n"
            'here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"\n'
            f'rm -f "$here/DONE" "$here/FAILED"; {RUNNING_MARK}\n'
            f'{python} -m tsg_cases.run_case{seeding} periodic --scale {scale} --np "${{TSG_NP:-{ranks}}}" --out "$here" {options}'
            ' 2>&1 | tee "$here/run.out"\nstatus=${PIPESTATUS[0]}\nrm -f "$here/RUNNING"\n'
            'if [ $status -eq 0 ]; then touch "$here/DONE"; else echo $status > "$here/FAILED"; fi\nexit $status\n')
        (run_dir / "run.sh").chmod(0o755)
        names.append(name)
    every = listed + [name for name in names if name not in listed]
    listing.write_text("\n".join(every) + "\n")
    (sweep / "sweep.slurm").write_text(
        "#!/usr/bin/env bash\n"
        f"#SBATCH --job-name=tsg-sweep\n#SBATCH --array=0-{len(every) - 1}\n#SBATCH --ntasks={ranks}\n"
        "#SBATCH --time=24:00:00\n#SBATCH --output=%x-%a.out\n"
        "# One array task per line of runs.txt; finished runs (DONE) are skipped, so resubmitting resumes.\n"
        "# A paper-scale run is a chain: its task submits the next job of its own index (segment.sh).\n"
        "# The sweep's folder as written (SLURM runs a copy of this script elsewhere; TSG_SWEEP overrides it).\n"
        f'sweep="${{TSG_SWEEP:-{sweep.resolve()}}}"\n'
        'name=$(sed -n "$((SLURM_ARRAY_TASK_ID + 1))p" "$sweep/runs.txt")\n'
        '[ -f "$sweep/$name/DONE" ] && exit 0\n'
        'TSG_NP=$SLURM_NTASKS TSG_JOB_SCRIPT="$sweep/sweep.slurm" exec "$sweep/$name/run.sh"\n')
    return [sweep / n for n in names]


def segmented_run_script(python: str, seeding: str, options: str, ranks: int) -> str:
    """run.sh of a paper-scale run (9-16 core-hours per simulated second): a segment of a job chain
    (cases/slurm/segment.sh: prepared once, restart files every 20 000 steps, continued from the newest
    one when started again, locally by `tsg-sweep run` or as the next job of its array index), so that
    no run is lost to a time limit or an interruption. DONE and FAILED (the error line) come from
    segment.sh; a segment that ended before the run did leaves neither, and the next one continues."""
    return (
        "#!/usr/bin/env bash\n"
        "# One paper-scale run of the sweep, in segments (cases/slurm/segment.sh; docs/cluster.md): started\n"
        "# again, it continues from its newest restart file. Its state: RUNNING / DONE / FAILED here.\n"
        'here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"\n'
        f'np="${{TSG_NP:-{ranks}}}"\n'
        'launch=""\n'
        'if [ -n "${SLURM_JOB_ID:-}" ]; then launch="srun"; elif [ "$np" -gt 1 ]; then launch="mpirun -np $np --oversubscribe"; fi\n'
        f'{RUNNING_MARK}\n'
        f'TSG_OUT="$here" TSG_LAUNCH="${{TSG_LAUNCH-$launch}}" SLURM_NTASKS="$np" \\\n'
        f'  TSG_RUN_CASE="${{TSG_RUN_CASE:-{python} -m tsg_cases.run_case}}" \\\n'
        f'  TSG_PREPARE="--scale paper{seeding} {options}" \\\n'
        f'  {shlex.quote(str(ROOT / "cases" / "slurm" / "segment.sh"))} periodic "${{TSG_JOB_SCRIPT:-/dev/null}}" \\\n'
        '  2>&1 | tee -a "$here/run.out"\n'
        'status=${PIPESTATUS[0]}\nrm -f "$here/RUNNING"\nexit $status\n')


def state(run_dir: Path) -> str:
    """done, failed (why), running (alive on this host, or on another host: not checked from here),
    interrupted (its process on this host is gone) or pending."""
    if (run_dir / "DONE").exists():
        return "done"
    if (run_dir / "FAILED").exists():
        why = (run_dir / "FAILED").read_text().strip()   # run.sh: the exit status; segment.sh: the error line
        return f"failed ({'exit ' if why.isdigit() else ''}{why})"
    if (run_dir / "RUNNING").exists():
        pid, host, job = ((run_dir / "RUNNING").read_text().split() + ["", "", ""])[:3]
        if host and host != socket.gethostname():   # e.g. a cluster node, seen from the login node
            return f"running on {host}{f' (job {job})' if job else ''}: not checked from this host"
        alive = pid.isdigit() and Path(f"/proc/{pid}").exists()
        return "running" if alive else "interrupted"
    return "pending"


def run_dirs(sweep: Path) -> list[Path]:
    listing = sweep / "runs.txt"
    if not listing.is_file():
        raise ParameterError(f"{sweep} is not a sweep directory (no runs.txt): write it first")
    return [sweep / name for name in listing.read_text().split()]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="tsg-sweep", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    w = sub.add_parser("write")
    w.add_argument("sweep", type=Path)
    w.add_argument("--scale", choices=["paper", "demo"], default="paper")
    w.add_argument("--np", type=int, default=4)
    seeding = w.add_mutually_exclusive_group()
    seeding.add_argument("--replicas", type=int, default=1, help="runs per setting, fill seeds 1 … R")
    seeding.add_argument("--seeds", type=int, nargs="+", default=None, metavar="K",
                         help="runs per setting with these fill seeds (e.g. a replacement for a run the guards stopped)")
    w.add_argument("--only", nargs="+", default=None, metavar="NAME", help="write only these settings")
    w.add_argument("-v", "--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                   help="applied to every run (e.g. shorter times)")
    r = sub.add_parser("run")
    r.add_argument("sweep", type=Path)
    r.add_argument("--only", nargs="*", default=None)
    s = sub.add_parser("status")
    s.add_argument("sweep", type=Path)
    rep = sub.add_parser("report")
    rep.add_argument("sweep", type=Path)
    rep.add_argument("--out", type=Path, default=None, help="default SWEEP_DIR/report")
    rep.add_argument("--start", default=None, help="analyse every run from this time on, s, or 'auto' (the latest "
                                                   "detected start of stationarity); default: the whole record")
    rep.add_argument("--parts", type=int, default=2, help="parts of the window in parts.md (default 2)")
    parser.add_argument("--debug", action="store_true", help="show the Python traceback of an error")
    args = parser.parse_args(argv)
    try:
        return run(args, parser)
    except (ParameterError, OSError) as problem:
        if args.debug:
            raise
        print(f"tsg-sweep: error: {problem}", file=sys.stderr)
        return 2


def run(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    if args.command == "write":
        if args.np < 1:
            raise ParameterError(f"--np {args.np} is not allowed: number of MPI ranks per run, >= 1")
        written = write(args.sweep, args.scale, args.np, dict(args.var), args.replicas, args.only, args.seeds)
        print(f"{len(written)} runs written to {args.sweep} (run: tsg-sweep run {args.sweep}; "
              f"cluster: sbatch {args.sweep / 'sweep.slurm'})")
        return 0
    dirs = {str(d.relative_to(args.sweep)): d for d in run_dirs(args.sweep)}
    if args.command == "report":
        if args.parts < 1:
            raise ParameterError(f"--parts {args.parts} is not allowed: number of parts of the window, >= 1")
        return report(args.sweep, dirs, args.out or args.sweep / "report", window_start(args.start), args.parts)
    if args.command == "status":
        states = {name: state(d) for name, d in dirs.items()}
        for name, text in states.items():
            print(f"{name:<32}{text}")
        counts = {k: sum(v.startswith(k) for v in states.values()) for k in ("done", "running", "failed", "pending", "interrupted")}
        print("  ".join(f"{k} {v}" for k, v in counts.items()))
        return 0
    wanted = set(args.only or ())
    unknown = wanted - set(dirs) - {name.split("/")[0] for name in dirs}
    if unknown:
        parser.error(f"--only: no run named {', '.join(sorted(unknown))} in {args.sweep}")
    failures = 0
    for name, run_dir in dirs.items():
        if args.only is not None and name not in wanted and name.split("/")[0] not in wanted:
            continue
        before = state(run_dir)
        if before == "done" or before.startswith("running"):   # never two processes in one run directory
            gone = "" if before in ("done", "running") else f" (if no job runs it any more, delete {run_dir / 'RUNNING'})"
            print(f"{name}: {before}, skipped{gone}")
            continue
        print(f"{name}: running", flush=True)
        status = subprocess.run([str(run_dir / "run.sh")], env=dict(os.environ)).returncode
        now = state(run_dir)
        if status == 0 and now == "pending":   # a paper-scale segment stopped before the run's end
            now = "stopped before its end: tsg-sweep run continues it from its newest restart file"
        print(f"{name}: {now}{'' if now == 'done' else ', see run.out'}")
        failures += now != "done"
    return 1 if failures else 0

def window_start(text: str | None) -> float | str | None:
    """--start: None (the whole record), 'auto', or a time in s >= 0."""
    if text is None or text == "auto":
        return text
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not value >= 0.0:
        raise ParameterError(f"--start {text} is not allowed: a time in s >= 0, or 'auto'")
    return value


def detected_steady_start(runs: list[Run]) -> tuple[float, str]:
    """The latest start of stationarity of the domain flux over the runs (each in the first half of
    its record: tsg_analysis.validation.steady_start), and a line naming each."""
    from tsg_analysis.validation import STEADY_WITHIN, steady_start

    found = {}
    for run in runs:
        start = steady_start(run)
        if start is None:
            raise ParameterError(f"--start auto: {run.path} has too short a domain-flux record to detect a steady state "
                                 "(fewer than 10 element blocks); give --start T")
        found[run.path] = start
    latest = max(found.values())
    names = ", ".join(f"{d.parent.name}/{d.name} {t:.3g}" for d, t in found.items())
    return latest, (f"stationary from (s; domain flux; pymbar's criterion, origin in the first {STEADY_WITHIN:.0%} "
                    f"of each record): {names}")


def report(sweep: Path, dirs: dict[str, Path], out: Path, start: float | str | None = None, parts: int = 2) -> int:
    from tsg_analysis.figures import plot_element_panels, plot_paper_mass_flow
    from tsg_analysis.model import AXIAL_VELOCITY, DOMAIN_FLUX, MASS_FLOW, SOLID_FRACTION, SPEED
    from tsg_analysis.run import Run
    from tsg_analysis.run_files import AnalysisInputError
    from tsg_analysis.summary import compare_runs, sweep_markdown, thermo_largest, write_sweep_csv
    from tsg_analysis.validation import (
        PAIR_CLAIMS,
        PAPER_MASS_FLOW,
        directions,
        directions_markdown,
        flux_parts,
        pair_markdown,
        pair_verdicts,
        parts_markdown,
    )

    settings: dict[str, list[Run]] = {}
    for name, run_dir in dirs.items():
        settings.setdefault(name.split("/")[0], [])
        if state(run_dir) == "done":
            settings[name.split("/")[0]].append(Run(run_dir))
    if not settings.get("reference"):
        raise ParameterError(f"{sweep}: the reference has no finished run yet (tsg-sweep status {sweep})")
    variants = {name: runs for name, runs in settings.items() if name != "reference" and runs}
    window, detection, begin = "the whole sampling record of every run", "", None
    if start == "auto":
        begin, detection = detected_steady_start([d for runs in settings.values() for d in runs])
        window = f"every run from t = {begin:.4g} s, the latest detected steady start"
    elif isinstance(start, float):
        begin, window = start, f"every run from t = {start:.4g} s"
    try:
        rows = compare_runs(settings["reference"], variants, begin)
        pairs = [claim for claim in PAIR_CLAIMS if settings.get(claim.first) and settings.get(claim.second)]
        pair_rows = [row for first, second in dict.fromkeys((c.first, c.second) for c in pairs)
                     for row in compare_runs(settings[second], {f"{first} − {second}": settings[first]}, begin)]
        flux_by_part = {name: flux_parts(runs, parts, begin) for name, runs in settings.items() if runs}
    except AnalysisInputError as problem:
        raise ParameterError(f"--start {start}: {problem}") from None
    out.mkdir(parents=True, exist_ok=True)
    counts = ", ".join(f"{name} {len(runs)}/{sum(1 for n in dirs if n.split('/')[0] == name)}"
                       for name, runs in settings.items())
    failed = [f"{name} ({state(d)})" for name, d in dirs.items() if state(d).startswith("failed")]
    releases = {name: [thermo_largest(run, "fast") for run in runs] for name, runs in settings.items() if runs}
    counted = "; ".join(f"{name} {', '.join('-' if n is None else str(int(n)) for n in values)}"
                        for name, values in releases.items())
    header = f"Sweep {sweep}: finished runs per setting (replicas combined): {counts}." + (
        f" Failed, left out: {', '.join(failed)}." if failed else "") + f" Window: {window}." + (
        f" {detection}." if detection else "") + (
        f" Squeeze releases counted per run (check/contact fast_speed; '-': not counted): {counted}." if any(
            n is not None for values in releases.values() for n in values) else "") + "\n\n"
    (out / "comparison.md").write_text(header + sweep_markdown(rows), encoding="utf-8")
    write_sweep_csv(rows, out / "comparison.csv")
    verdicts = directions(rows)
    table = directions_markdown([v for v in verdicts if v.claim.variant in variants])
    (out / "directions.md").write_text(header + "Direction of each variant's difference from the reference: the seed "
                                       "paper's and ours (significant at 95 %, else 'not resolved').\n\n" + table,
                                       encoding="utf-8")
    written = "comparison.md, comparison.csv, directions.md, parts.md, mass-flow.png, elements.png"
    if pairs:
        (out / "splits.md").write_text(header + "The particle–particle-only and particle–geometry-only variations side by "
                                       "side (Figs. 13–15): two variations in one group, or one changing a quantity more "
                                       "than the other.\n\n" + pair_markdown(pair_verdicts(rows, pair_rows, pairs), pairs),
                                       encoding="utf-8")
        written += ", splits.md"
    flux = {r.variant: r.difference for r in rows if r.quantity == MASS_FLOW and r.scope == DOMAIN_FLUX}
    plot_paper_mass_flow(out / "mass-flow.png", [(name, flux.get(name), PAPER_MASS_FLOW.get(name)) for name in variants],
                         PAPER_MASS_FLOW["reference"])
    plot_element_panels(out / "elements.png", rows, [SOLID_FRACTION, SPEED, AXIAL_VELOCITY])
    (out / "parts.md").write_text(header + f"Domain flux in {parts} consecutive equal parts of the window (replica "
                                  "window means ± 95 %): does a difference persist as the start-up fades, and has "
                                  "the flux stopped drifting?\n\n" + parts_markdown(flux_by_part),
                                  encoding="utf-8")
    print(header + table + "\n" + parts_markdown(flux_by_part) +
          f"\nwritten: {out}/{written}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
