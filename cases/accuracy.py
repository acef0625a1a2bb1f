"""Accuracy against cost: ladders of each fidelity setting against a reference run (issue 15).

    tsg-accuracy STUDY_DIR [--case periodic] [--scale demo] [--np 1] [--holdup-g G]
                 [--seed S | --replicas R] [--from-states DIR] [-v NAME VALUE ...] [--ladder SETTING VALUE [VALUE ...] ...]
                 [--tolerance 5%] [--tolerance-quantity "solid fraction"] [--no-run]

The reference is the case at the scale's settings with your options (-v, --np, --mesh-tolerance,
...). Each ladder changes one setting of it:

    dt_fraction     time step as a fraction of the Rayleigh time (-v dt_fraction)
    mesh_tolerance  mesh tolerance, m (--mesh-tolerance)
    d_mean          mean particle diameter, m, at the same hold-up mass (-v d_mean)
    domain          the case: periodic, nonperiodic or full (the reference's physical variables
                    carried over; --domain-var sets the other case's run times)
    sampling        fractions of the reference's sampling window: no run, the reference's own
                    record truncated (its window bias and statistical error against run time)
    screw_drive     control: stock or corotating (-v screw_drive); its error must be "not resolved"
    np              control: MPI ranks; its error must be "not resolved"

dt_fraction and d_mean points keep the reference's output interval in simulated time
(stats_every and thermo_every scaled by the ratio of the time steps), so every point has as many
samples as the reference. Every point is one run of tsg-run-case in STUDY_DIR/<setting>-<value>
(the reference in STUDY_DIR/reference) with point.json (its command and state); a finished point
with the same command is reused, so an interrupted study resumes where it stopped. With
--replicas R the reference and every run point are R runs that differ only in the fill seed
(1 ... R), in <point>/seed-K: their window means give the intervals where each window is too short
for a time-series interval (docs/statistics.md), and a point's cost is that of all its replicas.
With --from-states DIR every run continues the kept state DIR/seed-K of its fill seed K (cases/states.py,
e.g. cases/states/periodic-demo: steady states) instead of starting from the fill, so that the
study measures at steady state; the state fixes the fill and the machine, so only the dt_fraction,
sampling and np ladders apply.

Per point and key quantity (mass flow by the flux estimator, per-element solid fraction, axial
velocity and speed, mean residence time where complete records exist): the error against the
reference ± 95 % interval ("not resolved" when the interval covers zero, never a bare number) and
the cost (loop wall time, core-seconds, core-seconds per simulated second, particle-steps per
second). Outputs in STUDY_DIR: accuracy.json, accuracy.csv, accuracy.md (tables) and
accuracy-<quantity>.png (error against cost, log-log, one curve per setting). With --tolerance,
the cheapest point whose every scope of --tolerance-quantity meets it (the upper end of the error's
interval within the tolerance), or "none resolved". Exit status 0; 1 when a point failed or a
control resolved a difference; 2 for a bad option.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import resource
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from tsg_analysis.accuracy import (
    RECOMMENDATION_TOLERANCES,
    PointError,
    RunCost,
    Tolerance,
    cheapest,
    point_errors,
    quantity_verdict,
    recommend,
    replica_key_estimates,
    resolved_scopes,
    run_cost,
    sampling_ends,
    worst_relative,
)
from tsg_analysis.model import KEY_UNITS, SOLID_FRACTION, Key
from tsg_analysis.run import Run
from tsg_analysis.run_files import AnalysisInputError
from tsg_analysis.uncertainty import Estimate
from tsg_cases.case_parameters import CASES, RUNNER_SET, ParameterError, check_names, defined_variables
from tsg_cases.command_line import run_reporting
from tsg_cases.run_case import DEFAULT_FILL_SEED, SCALES

SETTINGS = {
    "dt_fraction": "time step, fraction of the Rayleigh time",
    "mesh_tolerance": "mesh tolerance, m",
    "d_mean": "mean particle diameter at equal hold-up mass, m",
    "domain": "case (domain)",
    "sampling": "fraction of the reference's sampling window",
    "screw_drive": "screw drive (control)",
    "np": "MPI ranks (control)",
}
CONTROLS = ("screw_drive", "np")
FROM_STATE_SETTINGS = ("dt_fraction", "sampling", "np")   # the ladders a run from a kept state can change
# run control: not carried from the reference to a point of another domain (each case has its own)
RUN_TIMES = ("t_startup", "t_sample", "t_run", "t_max_startup")
TOLERANCE_QUANTITIES = tuple(KEY_UNITS)


class StudyError(Exception):
    """A bad option or a study directory that does not fit the options: one line for the user."""


@dataclass
class Point:
    setting: str  # "reference" or one of SETTINGS
    value: str
    case: str
    argvs: list[list[str]]  # tsg-run-case arguments without --out, one per replica
    run_dir: Path  # the point's directory
    run_dirs: list[Path]  # one per replica: run_dir itself, or run_dir/seed-K
    state: str = "pending"
    wall_seconds: float | None = None  # of the whole point, preparation included
    cpu_seconds: float | None = None  # user + system time of the runner and lmp: less sensitive to the machine's load
    errors: list[PointError] = field(default_factory=list)
    cost: RunCost | None = None
    note: str = ""

    @property
    def label(self) -> str:
        return "reference" if self.setting == "reference" else f"{self.setting} {self.value}"

    @property
    def argv(self) -> list[str]:
        """The first replica's arguments (all replicas differ only in --seed)."""
        return self.argvs[0] if self.argvs else []


def number(text: str, what: str, low: float, high: float) -> float:
    try:
        value = float(text)
    except ValueError:
        raise StudyError(f"--ladder {what} {text} is not allowed: a number, {low:g} < value <= {high:g}") from None
    if not low < value <= high:
        raise StudyError(f"--ladder {what} {text} is not allowed: {low:g} < value <= {high:g}")
    return value


def check_ladder(setting: str, values: list[str]) -> None:
    if setting not in SETTINGS:
        raise StudyError(f"--ladder {setting} is not allowed: use one of {', '.join(SETTINGS)}")
    if not values:
        raise StudyError(f"--ladder {setting}: give at least one value")
    for value in values:
        if setting == "dt_fraction":
            number(value, setting, 0.0, 0.3)
        elif setting == "mesh_tolerance":
            number(value, setting, 0.0, 1e-3 * (1 - 1e-12))
        elif setting == "d_mean":
            number(value, setting, 0.0, 0.01)
        elif setting == "sampling":
            number(value, setting, 0.0, 1.0)
        elif setting == "np" and not (value.isdigit() and int(value) >= 1):
            raise StudyError(f"--ladder np {value} is not allowed: a number of MPI ranks, >= 1")
        elif setting == "domain" and value not in CASES:
            raise StudyError(f"--ladder domain {value} is not allowed: use one of {', '.join(CASES)}")
        elif setting == "screw_drive" and value not in ("stock", "corotating"):
            raise StudyError(f"--ladder screw_drive {value} is not allowed: stock or corotating")


class Study:
    def __init__(self, args: argparse.Namespace) -> None:
        self.args = args
        self.dir: Path = args.study.resolve()
        self.user_vars = dict(args.var)
        check_names(self.user_vars, args.case)
        scale = SCALES[args.scale]
        # the reference's variables as the runner will use them: case defaults < scale < user
        self.reference_vars = {**defined_variables(args.case), **{k: str(v) for k, v in scale["vars"].items()},
                               **{k: str(v) for k, v in scale["times"][args.case].items()}, **self.user_vars}
        self.reference_tolerance: float = args.mesh_tolerance or scale["tolerance"]
        for setting, *values in args.ladder:
            guard = float(self.reference_vars["guard_step_fraction"])
            if setting == "dt_fraction" and max(float(v) for v in values) > guard:
                raise StudyError(f"--ladder dt_fraction {max(values, key=float)} is above the time-step guard "
                                 f"guard_step_fraction = {guard:g}: the run would stop; add -v guard_step_fraction "
                                 f"{float(max(values, key=float)) + 1e-4:g} (a little above: the guard compares floating-point ratios)")

    @property
    def seeds(self) -> list[int]:
        if self.args.replicas > 1:
            return list(range(1, self.args.replicas + 1))
        return [self.args.seed if self.args.seed is not None else DEFAULT_FILL_SEED]

    def point(self, setting: str, value: str, case: str, np_: int, variables: dict[str, str],
              tolerance: float | None, run_dir: Path) -> Point:
        """A run point: one run per replica seed."""
        argvs = [self.argv(case, np_, variables, tolerance, seed) for seed in self.seeds]
        dirs = [run_dir / f"seed-{seed}" for seed in self.seeds] if self.args.replicas > 1 else [run_dir]
        return Point(setting, value, case, argvs, run_dir, dirs)

    def argv(self, case: str, np_: int, variables: dict[str, str], tolerance: float | None, seed: int) -> list[str]:
        argv = [case, "--scale", self.args.scale, "--np", str(np_)]
        if self.args.from_states is not None:
            argv += ["--from-state", str((self.args.from_states / f"seed-{seed}").resolve())]
        else:
            argv += ["--seed", str(seed)]
        if self.args.holdup_g is not None:
            argv += ["--holdup-g", str(self.args.holdup_g)]
        if tolerance is not None:
            argv += ["--mesh-tolerance", repr(tolerance)]
        for name, value in variables.items():
            argv += ["-v", name, value]
        return argv

    def time_step_ratio(self, variables: dict[str, str]) -> float:
        """dt(reference) / dt(point): dt is dt_fraction x the Rayleigh time, which scales with the
        smallest diameter and so, at a fixed PSD width, with d_mean (cases/include/timestep.in)."""
        ref = self.reference_vars
        return (float(ref["dt_fraction"]) * float(ref["d_mean"])) / \
               (float(variables.get("dt_fraction", ref["dt_fraction"])) * float(variables.get("d_mean", ref["d_mean"])))

    def point_vars(self, changed: dict[str, str]) -> dict[str, str]:
        """The user's variables with `changed`; output intervals kept in simulated time."""
        variables = {**self.user_vars, **changed}
        ratio = self.time_step_ratio(variables)
        if abs(ratio - 1) > 1e-12:
            for name in ("stats_every", "thermo_every"):
                variables[name] = str(max(1, round(int(float(self.reference_vars[name])) * ratio)))
        return variables

    def domain_vars(self, case: str) -> dict[str, str]:
        """The reference's physical variables that the other case also has (its defaults differ, e.g.
        cohesion), without run times and runner-set names; --domain-var on top."""
        other = defined_variables(case)
        carried = {k: v for k, v in self.reference_vars.items()
                   if k in other and k not in RUNNER_SET and k not in RUN_TIMES and k not in ("x_lo", "x_hi", "boundary_x",
                                                                                         "procs_x", "buffer")}
        given = dict(self.args.domain_var)
        check_names(given, case, "--domain-var")
        return {**carried, **given}

    def is_reference(self, setting: str, value: str) -> bool:
        """The reference's own value of a setting (a point that would repeat the reference)."""
        if setting in ("dt_fraction", "d_mean"):
            return math.isclose(float(value), float(self.reference_vars[setting]))
        if setting == "screw_drive":
            return value == self.reference_vars[setting]
        if setting == "mesh_tolerance":
            return math.isclose(float(value), self.reference_tolerance)
        if setting == "np":
            return int(value) == self.args.np
        return setting == "domain" and value == self.args.case

    def points(self) -> list[Point]:
        a = self.args
        reference = self.point("reference", "", a.case, a.np, dict(self.user_vars), a.mesh_tolerance,
                               self.dir / "reference")
        points = [reference]
        for setting, *values in a.ladder:
            for value in values:
                run_dir = self.dir / f"{setting}-{value}"
                if setting == "sampling":
                    points.append(Point(setting, value, a.case, [], reference.run_dir, reference.run_dirs))
                    continue
                case, np_, tolerance, variables = a.case, a.np, a.mesh_tolerance, dict(self.user_vars)
                if setting in ("dt_fraction", "d_mean", "screw_drive"):
                    variables = self.point_vars({setting: value})
                elif setting == "mesh_tolerance":
                    tolerance = float(value)
                elif setting == "np":
                    np_ = int(value)
                elif setting == "domain":
                    case, variables = value, self.domain_vars(value)
                point = self.point(setting, value, case, np_, variables, tolerance, run_dir)
                if self.is_reference(setting, value):
                    raise StudyError(f"--ladder {setting} {value} is the reference's own setting: leave it out "
                                     "(the reference is every ladder's point of comparison)")
                points.append(point)
        return points

    # ---- running -------------------------------------------------------------------------------

    def state(self, point: Point) -> str:
        """done when every replica is; failed when one failed; else pending."""
        states, point.wall_seconds, point.cpu_seconds = [], None, None
        for argv, run_dir in zip(point.argvs, point.run_dirs):
            record = run_dir / "point.json"
            if not record.is_file():
                states.append("pending")
                continue
            saved = json.loads(record.read_text())
            if saved.get("argv") != argv:
                raise StudyError(f"{run_dir} was run with other options ({' '.join(saved.get('argv', []))}): "
                                 "remove it or use another study directory")
            point.wall_seconds = (point.wall_seconds or 0.0) + (saved.get("wall_seconds") or 0.0)
            point.cpu_seconds = (point.cpu_seconds or 0.0) + (saved.get("cpu_seconds") or 0.0)
            states.append(str(saved.get("state", "pending")))
        failed = [x for x in states if x.startswith("failed")]
        return failed[0] if failed else "done" if all(x == "done" for x in states) else "pending"

    def run_point(self, point: Point) -> None:
        """Runs the replicas not yet done; the point's state and cost from all of them."""
        status = 0
        for argv, run_dir in zip(point.argvs, point.run_dirs):
            record = run_dir / "point.json"
            if record.is_file() and json.loads(record.read_text()).get("state") == "done":
                continue
            run_dir.mkdir(parents=True, exist_ok=True)
            command = [sys.executable, "-m", "tsg_cases.run_case", *argv, "--out", str(run_dir)]
            record.write_text(json.dumps({"argv": argv, "state": "running"}, indent=1) + "\n")
            name = run_dir.relative_to(self.dir)
            print(f"[accuracy] {point.label}: running ({name})", flush=True)
            start, before = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
            with open(run_dir / "run.out", "w") as out:
                status = subprocess.run(command, stdout=out, stderr=subprocess.STDOUT).returncode
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            wall = time.perf_counter() - start
            cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
            state = "done" if status == 0 else f"failed (exit {status})"
            record.write_text(json.dumps({"argv": argv, "state": state, "exit_status": status, "wall_seconds": wall,
                                          "cpu_seconds": cpu,
                                          "finished": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}, indent=1) + "\n")
            print(f"[accuracy] {point.label}: {state} in {wall:.0f} s ({name})", flush=True)
            if status != 0:  # the runner's one-line reason, for the table
                lines = [line for line in (run_dir / "run.out").read_text(errors="replace").splitlines() if line.strip()]
                point.note = lines[-1][:300] if lines else ""
                break
        point.state = self.state(point)

    # ---- analysis ------------------------------------------------------------------------------

    def analyse(self, points: list[Point]) -> dict[Key, Estimate] | None:
        reference = points[0]
        if reference.state != "done":
            for p in points:
                p.note = "no reference yet"
            return None
        ref_runs = [Run(d) for d in reference.run_dirs]
        ref_estimates = replica_key_estimates(ref_runs)
        ref_zones = ref_runs[0].zones
        ref_costs = [run_cost(run) for run in ref_runs]
        reference.cost = RunCost.of_replicas(ref_costs)
        sampling = [p for p in points if p.setting == "sampling"]
        if sampling:
            fractions = [float(p.value) for p in sampling]
            ends = [sampling_ends(run, fractions) for run in ref_runs]  # [replica][fraction]
            for k, p in enumerate(sampling):
                p.state = "done"
                mine = [replica_ends[k] for replica_ends in ends]
                p.cost = RunCost.of_replicas([c.until(end) for c, end in zip(ref_costs, mine)])
                try:
                    p.errors = point_errors(ref_estimates, replica_key_estimates(ref_runs, mine), sampling=True)
                except AnalysisInputError as problem:
                    p.note = str(problem)
        for p in points[1:]:
            if p.setting == "sampling" or p.state != "done":
                continue
            try:
                runs = [Run(d) for d in p.run_dirs]
                p.cost = RunCost.of_replicas([run_cost(run) for run in runs])
                estimates = replica_key_estimates(runs, reference_zones=ref_zones if p.case != reference.case else None)
                p.errors = point_errors(ref_estimates, estimates)
            except AnalysisInputError as problem:
                p.note = str(problem)
        return ref_estimates


def quantities_of(points: list[Point]) -> list[str]:
    return [q for q in KEY_UNITS if any(e.quantity == q for p in points for e in p.errors)]


def cell(errors: list[PointError], quantity: str) -> str:
    """One table cell: the worst resolved error of a quantity over its scopes, or why there is none."""
    mine = [e for e in errors if e.quantity == quantity]
    if not mine:
        return "-"
    short = sum(not e.resolved_inputs for e in mine)
    resolved = resolved_scopes(errors, quantity)
    sampling = mine[0].difference is None
    usable = [e for e in mine if e.resolved_inputs]
    if not usable:
        return f"window too short ({short}/{len(mine)} scopes)"
    suffix = f"; {short} scopes too short" if short else ""
    if sampling:
        worst, _ = worst_relative(usable, quantity)
        return f"bias + statistical ≤ ±{worst:.1%} (95 %){suffix}" if math.isfinite(worst) else f"no relative scale{suffix}"
    if not resolved:
        worst, _ = worst_relative(usable, quantity)
        within = f" (|error| ≤ {worst:.1%})" if math.isfinite(worst) else ""
        return f"not resolved{within}{suffix}"
    biggest = max(resolved, key=lambda e: abs(e.difference.relative) if e.difference and math.isfinite(e.difference.relative) else 0)
    d = biggest.difference
    assert d is not None
    relative = f"{d.relative:+.1%}" if math.isfinite(d.relative) else f"{d.value:+.3g}"
    return f"resolved in {len(resolved)}/{len(mine)}: largest {relative} ± {d.half_width / abs(biggest.reference.mean):.1%} " \
           f"({biggest.scope}){suffix}"


def write_outputs(study: Study, points: list[Point], tolerance: Tolerance | None, tolerance_quantity: str) -> dict:
    out = study.dir
    quantities = quantities_of(points)
    # a control's every quantity and scope together: simultaneous intervals (5 % false alarms per control)
    controls_resolved = [f"{p.label}: {e.quantity} {e.scope}" for p in points if p.setting in CONTROLS
                         for e in resolved_scopes(p.errors)]
    choice = None
    if tolerance is not None:
        candidates = {p.label: (p.cost.core_seconds if p.cost else math.nan, p.errors) for p in points[1:]
                      if p.errors and p.setting not in CONTROLS}
        choice = cheapest(candidates, tolerance_quantity, tolerance)
    result = {
        "case": study.args.case, "scale": study.args.scale,
        "reference": {"argv": points[0].argv, "state": points[0].state,
                      # the reference's value of each ladder setting (tsg_analysis.systematics reads them)
                      "settings": {"dt_fraction": study.reference_vars["dt_fraction"],
                                   "d_mean": study.reference_vars["d_mean"],
                                   "mesh_tolerance": repr(study.reference_tolerance)},
                      "from_states": None if study.args.from_states is None else str(study.args.from_states)},
        "cost_measure": "core_seconds: ranks x LIGGGHTS loop time of the run (start-up + sampling) that gave the number",
        "points": [{"label": p.label, "setting": p.setting, "value": p.value, "case": p.case, "run_dir": p.run_dir.name,
                    "replica_dirs": [str(d.relative_to(study.dir)) for d in p.run_dirs], "state": p.state, "note": p.note, "argv": p.argv,
                    "cost": p.cost.as_dict() if p.cost else None,
                    "wall_seconds_including_preparation": p.wall_seconds,
                    "cpu_seconds_including_preparation": p.cpu_seconds,
                    "verdicts": {q: quantity_verdict(p.errors, q, tolerance) for q in quantities} if tolerance else None,
                    "errors": [e.as_dict() for e in p.errors]} for p in points],
        "controls_resolved": controls_resolved,
        "tolerance": None if tolerance is None else {"quantity": tolerance_quantity, "value": tolerance.value,
                                                     "relative": tolerance.relative,
                                                     "cheapest": choice.label if choice else None,
                                                     "message": choice.message if choice else None},
    }
    result["recommendations"] = recommendations(points, quantities)
    (out / "accuracy.json").write_text(json.dumps(result, indent=1) + "\n")
    with open(out / "accuracy.csv", "w", newline="", encoding="utf-8") as stream:
        writer = csv.writer(stream)
        writer.writerow(["point", "setting", "value", "quantity", "unit", "scope", "reference_mean", "reference_half_width",
                         "value_mean", "value_half_width", "error", "error_half_width", "significant", "resolved_inputs",
                         "error_bound", "relative_bound", "text", "core_seconds", "core_seconds_per_simulated_second",
                         "particle_steps_per_second"])

        def num(v: float | None) -> object:
            return "" if v is None or not math.isfinite(v) else f"{v:.6g}"

        for p in points:
            c = p.cost
            for e in p.errors:
                d = e.difference
                # a difference within its interval has no value to print: only its interval
                writer.writerow([p.label, p.setting, p.value, e.quantity, KEY_UNITS[e.quantity], e.scope,
                                 num(e.reference.mean), num(e.reference.half_width), num(e.value.mean),
                                 num(e.value.half_width), num(d.value) if d and d.significant else "",
                                 num(e.half_width), e.significant, e.resolved_inputs, num(e.bound), num(e.relative_bound),
                                 e.text(), num(c.core_seconds if c else None),
                                 num(c.core_seconds_per_simulated_second if c else None),
                                 num(c.particle_steps_per_second if c else None)])
    (out / "accuracy.md").write_text(markdown(study, points, quantities, controls_resolved, tolerance, tolerance_quantity, choice),
                                  encoding="utf-8")
    figures(out, points, quantities)
    return result


def recommendations(points: list[Point], quantities: list[str]) -> list[dict]:
    """For a relative tolerance of 2 / 5 / 10 % and each quantity, the cheapest setting of the
    time-step ladder shown to be within it (tsg_analysis.accuracy.recommend; cost per simulated
    second, so that points of other windows compare)."""
    reference = points[0]
    ladder = {p.label: (p.cost.core_seconds_per_simulated_second if p.cost else math.nan, p.errors)
              for p in points[1:] if p.setting == "dt_fraction" and p.errors}
    if reference.cost is None or not ladder:
        return []
    rate = reference.cost.core_seconds_per_simulated_second
    rows = []
    for value in RECOMMENDATION_TOLERANCES:
        tolerance = Tolerance(value, True)
        for quantity in quantities:
            choice = recommend(ladder, rate, quantity, tolerance)
            rows.append({"tolerance": value, "quantity": quantity, "setting": choice.label,
                         "core_hours_per_simulated_second": None if choice.cost is None else choice.cost / 3600,
                         "message": choice.message})
    return rows


def markdown(study: Study, points: list[Point], quantities: list[str], controls_resolved: list[str],
             tolerance: Tolerance | None, tolerance_quantity: str, choice) -> str:
    lines = [f"# Accuracy against cost: {study.args.case} case, {study.args.scale} scale", "",
             f"Reference: `tsg-run-case {' '.join(points[0].argv)}`" + (
                 f" (seed 1; seeds 1 ... {study.args.replicas}): every run point is {study.args.replicas} "
                 "replicas (fill seeds), combined (replica window means where a window is too short for a "
                 "time-series interval); costs are those of all replicas" if study.args.replicas > 1 else ""), "",
             "Error of each point against the reference, the largest over the scopes (elements) of a quantity, "
             "relative to the reference value; ± 95 % interval. 'not resolved': every scope's interval covers "
             "zero (|error| ≤ the bound shown). Sampling: the reference's own record truncated, its "
             "bias against the whole record plus its statistical half-width. Cost: ranks × LIGGGHTS loop time "
             "of the run that gave the number (wall clock: it grows with the machine's load); CPU s: user + system "
             "time of the whole point, preparation included.", ""]
    header = ["point", "state", "simulated s", "steps / sim-s", "core-s", "core-s / sim-s", "particle-steps / s",
              "CPU s (with preparation)"] + \
             [f"{q} ({KEY_UNITS[q]})" for q in quantities]
    lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for p in points:
        c = p.cost
        costs = [f"{c.simulated_seconds:.4g}", f"{c.steps_per_simulated_second:.4g}", f"{c.core_seconds:.4g}",
                 f"{c.core_seconds_per_simulated_second:.4g}",
                 f"{c.particle_steps_per_second:.3g}"] if c else ["-"] * 5
        costs.append(f"{p.cpu_seconds:.4g}" if p.cpu_seconds is not None and p.setting != "sampling" else "-")
        state = p.state + (f" ({p.note})" if p.note else "")
        cells = [cell(p.errors, q) if p.setting != "reference" else "(reference)" for q in quantities]
        lines.append("| " + " | ".join([p.label, state, *costs, *cells]) + " |")
    lines.append("")
    control_points = [p for p in points if p.setting in CONTROLS and p.errors]
    waiting = [p.label for p in points if p.setting in CONTROLS and not p.errors]
    parts = []
    if controls_resolved:
        parts.append("**resolved differences: " + "; ".join(controls_resolved) + "** (the error estimate is not trustworthy)")
    elif control_points:
        parts.append(f"{', '.join(p.label for p in control_points)}: no difference resolved")
    if waiting:
        parts.append(f"not analysed: {', '.join(waiting)} (not finished)")
    if parts:
        lines += ["Controls (must come out not resolved): " + "; ".join(parts) + ".", ""]
    if tolerance is not None and choice is not None:
        lines += [f"Tolerance {tolerance.text()} on {tolerance_quantity}, every scope, the upper end of the 95 % "
                  f"interval of the error: cheapest point **{choice.message}**.", ""]
    rows = recommendations(points, quantities)
    if rows:
        lines += ["The time step per tolerance: the cheapest setting shown to be within it (every scope, the upper end "
                  "of the 95 % interval of the error), a coarser point against the reference or the reference against "
                  "every finer point:", "", "| tolerance | quantity | cheapest setting | core-hours per simulated s |",
                  "|---|---|---|---|"]
        for r in rows:
            hours = r["core_hours_per_simulated_second"]
            lines.append(f"| {r['tolerance']:.0%} | {r['quantity']} | {r['message']} | "
                         f"{'-' if hours is None else f'{hours:.3g}'} |")
        lines.append("")
    lines += ["## Per scope", "", "| point | quantity | scope | reference | point | error ± 95 % |", "|---|---|---|---|---|---|"]
    for p in points[1:]:
        for e in p.errors:
            unit = KEY_UNITS[e.quantity].strip("-")
            lines.append(f"| {p.label} | {e.quantity} | {e.scope} | {e.reference.text(unit)} | {e.value.text(unit)} | "
                         f"{e.text()} |")
    return "\n".join(lines) + "\n"


def figures(out: Path, points: list[Point], quantities: list[str]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    for quantity in quantities:
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        plotted = False
        for setting in [s for s in SETTINGS if any(p.setting == s for p in points)]:
            rows = []
            for p in points:
                if p.setting != setting or p.cost is None:
                    continue
                worst, resolved = worst_relative(p.errors, quantity)
                if math.isfinite(worst) and worst > 0:
                    rows.append((p.cost.core_seconds, worst, resolved or setting == "sampling"))
            if not rows:
                continue
            rows.sort()
            x, y, filled = zip(*rows)
            label = "sampling length (window bias + its 95 % half-width)" if setting == "sampling" else SETTINGS[setting]
            line, = ax.plot(x, y, "-", label=label)
            for xi, yi, fi in rows:
                ax.plot(xi, yi, "o" if fi else "v", color=line.get_color(), markerfacecolor=line.get_color() if fi else "none")
            plotted = True
        if plotted:
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.legend(fontsize=8)
        else:  # said, not left blank: every point's window was too short for an interval
            ax.text(0.5, 0.5, "no point has an error interval:\nevery window too short (see accuracy.md)",
                    ha="center", va="center", transform=ax.transAxes)
        ax.set_xlabel("cost of the run, core-seconds")
        ax.set_ylabel(f"relative error of {quantity}, largest over scopes")
        ax.set_title(f"{quantity}: filled = resolved (|Δ| + 95 % half-width);\nopen ▽ = not resolved (upper bound)", fontsize=9)
        fig.tight_layout()
        fig.savefig(out / f"accuracy-{quantity.replace(' ', '-').replace('/', '-')}.png", dpi=110)
        plt.close(fig)


def parse(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="tsg-accuracy", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("study", type=Path, help="study directory (one run directory per point)")
    parser.add_argument("--case", choices=CASES, default="periodic")
    parser.add_argument("--scale", choices=sorted(SCALES), default="demo")
    parser.add_argument("--np", type=int, default=1, help="MPI ranks of the reference and every point")
    parser.add_argument("--holdup-g", type=float, help="hold-up mass of the periodic domain, g")
    parser.add_argument("--seed", type=int, default=None, help="seed of the static fill (one run per point)")
    parser.add_argument("--replicas", type=int, default=1,
                        help="runs per point that differ only in the fill seed (1 ... R)")
    parser.add_argument("--mesh-tolerance", type=float, help="the reference's mesh tolerance, m (default: the scale's)")
    parser.add_argument("--from-states", type=Path, help="kept states DIR/seed-K that every run continues (fill seed K)")
    parser.add_argument("-v", "--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                        help="a variable of the reference (and every point)")
    parser.add_argument("--domain-var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                        help="a variable of the other cases of the domain ladder (e.g. t_run)")
    parser.add_argument("--ladder", nargs="+", action="append", default=[], metavar="SETTING VALUE",
                        help=f"a setting ({', '.join(SETTINGS)}) and its values")
    parser.add_argument("--tolerance", help="e.g. 5%% (relative) or 0.002 (absolute, in the quantity's unit)")
    parser.add_argument("--tolerance-quantity", default=SOLID_FRACTION, choices=TOLERANCE_QUANTITIES)
    parser.add_argument("--no-run", action="store_true", help="analyse the finished points only")
    parser.add_argument("--debug", action="store_true", help="show the Python traceback of an error")
    return parser.parse_args(argv)


def run(args: argparse.Namespace) -> int:
    for setting, *values in args.ladder:
        check_ladder(setting, values)
    if args.np < 1:
        raise StudyError(f"--np {args.np} is not allowed: number of MPI ranks, >= 1")
    if args.replicas < 1:
        raise StudyError(f"--replicas {args.replicas} is not allowed: runs per point that differ in the fill seed, >= 1")
    if args.replicas > 1 and args.seed is not None:
        raise StudyError(f"--seed {args.seed} is not allowed with --replicas {args.replicas}: the replicas' seeds are "
                         f"1 ... {args.replicas}")
    if args.from_states is not None:
        other = [setting for setting, *_ in args.ladder if setting not in FROM_STATE_SETTINGS]
        if other:
            raise StudyError(f"--ladder {other[0]} is not allowed with --from-states {args.from_states}: the states fix "
                             f"the fill and the machine (allowed: {', '.join(FROM_STATE_SETTINGS)})")
        if args.holdup_g is not None or args.mesh_tolerance is not None:
            raise StudyError(f"--{'holdup-g' if args.holdup_g is not None else 'mesh-tolerance'} is not allowed with "
                             f"--from-states {args.from_states}: the states fix the fill and the machine")
    if args.domain_var and not any(setting == "domain" for setting, *_ in args.ladder):
        raise StudyError(f"--domain-var {args.domain_var[0][0]}: there is no --ladder domain for it to apply to")
    tolerance = Tolerance.parse(args.tolerance) if args.tolerance is not None else None
    study = Study(args)
    points = study.points()
    labels = [p.label for p in points]
    if len(set(labels)) != len(labels):
        raise StudyError("a ladder value is given twice: " + ", ".join(sorted({x for x in labels if labels.count(x) > 1})))
    study.dir.mkdir(parents=True, exist_ok=True)
    for p in points:
        if p.setting != "sampling":
            p.state = study.state(p)
    failed = False
    for p in points:
        if p.setting == "sampling" or p.state == "done":
            continue
        if args.no_run:
            continue
        study.run_point(p)
        failed |= p.state != "done"
        if p.state != "done" and p.setting == "reference":
            print(f"[accuracy] the reference failed: see its run.out under {p.run_dir}", file=sys.stderr)
            return 1
        study.analyse(points)   # outputs after every point: a study cut short still has its tables
        write_outputs(study, points, tolerance, args.tolerance_quantity)
    study.analyse(points)
    result = write_outputs(study, points, tolerance, args.tolerance_quantity)
    print((study.dir / "accuracy.md").read_text(encoding="utf-8").split("## Per scope")[0])
    print(f"[accuracy] outputs: {study.dir / 'accuracy.json'}, accuracy.csv, accuracy.md, accuracy-*.png")
    if result["controls_resolved"]:
        print("[accuracy] a control resolved a difference: " + "; ".join(result["controls_resolved"]), file=sys.stderr)
    return 1 if failed or result["controls_resolved"] else 0


def main(argv: list[str] | None = None) -> int:
    args = parse(argv)
    return run_reporting("tsg-accuracy", lambda: run(args),
                         (StudyError, ParameterError, ValueError, AnalysisInputError, OSError), args.debug)


if __name__ == "__main__":
    sys.exit(main())
