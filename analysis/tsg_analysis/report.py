"""The report: analyse one or several run directories, draw the figures, and hand the numbers to
report_files.py for report.md, summary.json and the CSV tables.

Every part is produced independently: a part whose input is missing or unusable is listed under
"Not produced" with the reason, and the rest of the report is still written. Parts that average
over time (RTDs, element profiles, cross-sections, mean sensor flows, flows from dumps) use the
steady window decided from massflow.txt; a run that is not (known to be) steady is averaged over
its whole record and marked transient (Settings.require_steady: produce nothing instead). Every
mean carries its 95 % interval (uncertainty.py). The run's parameters (rpm, density) come from the
run directory (parameters.py), the screw pose from the screw dumps the run wrote.
"""
from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TypeVar

import numpy as np

from . import figures
from .cross_section import SolidFractionAccumulator
from .dumps import ParticleFrame, find_dump_files, iter_frames, read_dump_file, step_from_name
from .liggghts_log import parse_errors, parse_thermo, parse_warnings
from .massflow import PlaneFlowCounter, decide_steady_state
from .model import Report, RunAnalysis, Settings
from .profiles import element_profile, zone_residence_times
from .report_files import write_outputs
from .rtd import compare_rtds, rtd_statistics
from .run import Run
from .run_files import AnalysisInputError
from .snapshot import render_snapshot, screw_dumps_at
from .uncertainty import Estimate, difference

T = TypeVar("T")


def _attempt(run: RunAnalysis, part: str, action: Callable[[], None]) -> bool:
    """Run one part; an unusable input becomes a 'not produced' entry instead of an exception."""
    try:
        action()
    except AnalysisInputError as err:
        run.missing.append((part, str(err)))
        return False
    return True


def _need(value: T | None, reason: str) -> T:
    """A part's input, or the reason the part cannot be produced."""
    if value is None:
        raise AnalysisInputError(reason)
    return value


def _slug(label: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", label).strip("_") or "run"


def run_labels(run_dirs: list[Path]) -> list[str]:
    """Directory names, or as many trailing path parts as it takes to tell them apart."""
    parts = [Path(d).resolve().parts for d in run_dirs]
    for depth in range(1, max(len(p) for p in parts) + 1):
        labels = ["/".join(p[-depth:]) for p in parts]
        if len(set(labels)) == len(labels):
            return labels
    return [str(d) for d in run_dirs]


# ---- one run --------------------------------------------------------------------------------------

def _source(run: RunAnalysis) -> Run:
    return _need(run.source, f"{run.run_dir}: not a directory")


def _read_log(run: RunAnalysis) -> None:
    text = _source(run).log
    thermo = [block for block in parse_thermo(text) if block]
    warnings = parse_warnings(text)
    last = thermo[-1] if thermo else {}
    run.log_summary = {
        "last_step": int(last["Step"][-1]) if "Step" in last and len(last["Step"]) else None,
        "particles": int(last["Atoms"][-1]) if "Atoms" in last and len(last["Atoms"]) else None,
        "warnings": {w: warnings.count(w) for w in dict.fromkeys(warnings)},
        "errors": parse_errors(text),
    }


def _steady_window(run: RunAnalysis, settings: Settings) -> float:
    if settings.steady_window is not None:
        return settings.steady_window
    if run.parameters is None:
        raise AnalysisInputError("the steady-state window is one screw revolution, but the run's rpm is unknown "
                                 "(no usable params.json or TSG-PARAMETERS line; give --steady-window)")
    return run.parameters.revolution_s


def _decide_window(run: RunAnalysis, settings: Settings) -> None:
    source = _source(run)
    run.massflow = source.massflow
    run.notes.extend(run.massflow.issues)
    try:
        run.clock = source.clock
    except AnalysisInputError:  # a single row: the steady-state decision below says the record is too short
        run.clock = None
    run.steady = decide_steady_state(run.massflow, _steady_window(run, settings), settings.steady_tolerance)
    if run.steady.reached:
        run.window = (_need(run.steady.start_time, "steady state reached at an unknown time"), run.steady.end_time)
    elif not settings.require_steady:
        run.window, run.transient = (-math.inf, math.inf), True


def _require_window(run: RunAnalysis) -> tuple[float, float]:
    if run.window is not None:
        return run.window
    reason = "the run never reached steady state" if run.steady is not None else \
        "steady state is unknown without a usable massflow.txt"
    raise AnalysisInputError(f"no steady window: {reason} (without --require-steady the whole record is averaged)")


def _bounds(run: RunAnalysis) -> tuple[float | None, float | None]:
    """The window for Run's window rule: from the steady start to the end of the record, or the
    whole record of a transient run."""
    low, _ = _require_window(run)
    return (None, None) if run.transient else (low, None)


def _rtd_selection(run: RunAnalysis) -> np.ndarray:
    """Particles that left through the outlet (or made a periodic pass) inside the window."""
    return _source(run).records(*_bounds(run))


def _analyse_rtd(run: RunAnalysis) -> None:
    source = _source(run)
    run.rtd_means = source.residence_means(*_bounds(run))
    selected = _rtd_selection(run)
    records = source.residence
    samples = {"total": records.residence_time[selected]}
    samples.update({t: records.time_by_type[t][selected] for t in source.record_types()})
    run.rtd_stats["total"] = rtd_statistics(samples["total"], f"{run.label}: total RTD")
    run.rtd_samples["total"] = samples.pop("total")
    for scope, times in samples.items():
        if _attempt(run, f"RTD {scope}", lambda: run.rtd_stats.__setitem__(
                scope, rtd_statistics(times, f"{run.label}: {scope} RTD"))):
            run.rtd_samples[scope] = times


def _analyse_profile(run: RunAnalysis) -> None:
    zones = _need(run.zones, "zones.txt is needed to name the elements")
    source = _source(run)
    bounds = _bounds(run)
    estimates: dict[str, list[Estimate]] = {}
    blocks, records = 0, 0

    def from_elements() -> None:
        nonlocal blocks
        run.notes.extend(source.elements.issues)
        averages = source.element_averages(*bounds)
        estimates.update(averages.by_zone)
        blocks = int(averages.used.sum())
        run.holdup_residence = averages.holdup_residence
        run.throughput = averages.throughput
        holdup_residence_by_zone.extend(averages.element_holdup_residence)

    def from_residence() -> None:
        nonlocal records
        selected = _rtd_selection(run)
        estimates["residence_time"] = zone_residence_times(_need(run.records, "no usable residence.txt"), zones, selected)
        records = int(selected.sum())

    holdup_residence_by_zone: list[Estimate] = []
    produced = [_attempt(run, "element profiles: solid fraction and velocities", from_elements),
                _attempt(run, "element profiles: residence time per element (records)", from_residence)]
    if not produced[1] and holdup_residence_by_zone:   # no complete record in the window: Little's law per element
        estimates["residence_time"] = holdup_residence_by_zone
        run.notes.append("residence time per element from hold-up over throughput (Little's law; no complete "
                         "residence record in the window)")
    if any(produced):
        run.profile = element_profile(zones, estimates, blocks, records)


def _frames_in_window(run: RunAnalysis, paths: list[Path], issues: list[str]) -> Iterator[tuple[ParticleFrame, float]]:
    """Dump frames inside the window with their times (VTK files are skipped by name, unread)."""
    low, high = _require_window(run)
    clock = run.clock if run.transient else _need(run.clock, "the dump frames' times are unknown without massflow.txt")
    for path in paths:
        if path.suffix == ".vtk" and clock is not None and not run.transient and \
                not low <= clock.time(step_from_name(path)) <= high:
            continue
        for frame in iter_frames([path], issues):
            time = float(clock.time(frame.step)) if clock is not None else float(frame.step)
            if run.transient or low <= time <= high:
                yield frame, time


def _analyse_dumps(run: RunAnalysis, settings: Settings) -> None:
    paths, notes = find_dump_files(run.run_dir)
    run.notes.extend(notes)
    if not paths:
        parts = ("cross-section maps", "mass flow through zone boundaries") + (("snapshot",) if settings.snapshot else ())
        for part in parts:
            run.missing.append((part, f"no dumps/particles_*.txt or dumps/particles_*.vtk in {run.run_dir}"))
        return
    if settings.snapshot:
        _attempt(run, "snapshot", lambda: _snapshot(run, paths[-1], settings))

    def averaged_parts() -> None:
        _require_window(run)
        if run.zones is None:
            raise AnalysisInputError("zones.txt is needed to know where the element types are")
        accumulator = SolidFractionAccumulator({t: run.zones.ranges(t) for t in run.zones.types_present},
                                               settings.bin_size)
        planes = np.append(run.zones.x_start, run.zones.x_end[-1])
        counter: PlaneFlowCounter | None = None
        counter_problem = None
        issues: list[str] = []
        for frame, time in _frames_in_window(run, paths, issues):
            accumulator.add(frame)
            if counter is None and counter_problem is None:
                density = _particle_density(run, settings)
                counter_problem = _plane_counter_problem(run, frame, density)
                if counter_problem is None:
                    counter = PlaneFlowCounter(planes, _x_period(frame), density)
            if counter is not None:
                counter.add(frame, time)
        run.notes.extend(issues)
        if accumulator.frames == 0:
            raise AnalysisInputError(f"none of the {len(paths)} dump files has a frame inside the averaging window")
        run.maps = accumulator.maps()
        if counter is None:
            run.missing.append(("mass flow through zone boundaries", str(counter_problem)))
        else:
            _attempt(run, "mass flow through zone boundaries", lambda: setattr(run, "plane_flows", counter.result()))

    if not _attempt(run, "cross-section maps", averaged_parts):
        run.missing.append(("mass flow through zone boundaries", run.missing[-1][1]))


def _particle_density(run: RunAnalysis, settings: Settings) -> float | None:
    if settings.particle_density is not None:
        return settings.particle_density
    return run.parameters.rho_p if run.parameters is not None else None


def _plane_counter_problem(run: RunAnalysis, frame: ParticleFrame, density: float | None) -> str | None:
    if run.clock is None:
        return "frame times unknown without massflow.txt"
    if "mass" not in frame.columns and density is None:
        return "dumps carry no 'mass' column and the run's rho_p is unknown: give the particle density (--density)"
    periodic = _is_periodic(run)
    if frame.box is None and periodic:
        return "periodic run with VTK dumps: they carry no box, so wraps cannot be told from jumps (use text dumps)"
    if frame.box is None and periodic is None:
        return "VTK dumps carry no box, and neither params.json nor residence.txt says whether the domain is periodic"
    return None


def _is_periodic(run: RunAnalysis) -> bool | None:
    """From the run's record: params.json's case, residence.txt's '# axis:' header, or a periodic pass."""
    if run.parameters is not None and run.parameters.case is not None:
        return run.parameters.case == "periodic"
    path = run.run_dir / "residence.txt"
    if path.is_file():
        with open(path, encoding="utf-8", errors="replace") as stream:
            for line in stream:
                if not line.startswith("#"):
                    break
                if line.startswith("# axis:"):
                    return line.split(":", 1)[1].split(",")[0].strip() == "periodic"
    if run.records is not None and np.any(run.records.exit_reason == "pass"):
        return True
    return None


def _x_period(frame: ParticleFrame) -> float | None:
    if frame.box is not None and frame.box.periodic[0]:
        return float(frame.box.hi[0] - frame.box.lo[0])
    return None


def _snapshot(run: RunAnalysis, last_dump: Path, settings: Settings) -> None:
    frames, issues = read_dump_file(last_dump)
    run.notes.extend(issues)
    if not frames:
        raise AnalysisInputError(f"{last_dump}: no complete frame")
    frame = frames[-1]
    time = float(run.clock.time(frame.step)) if run.clock is not None else None
    screws, posed = screw_dumps_at(run.run_dir, frame.step), True
    if not screws:  # the screw surfaces as built: their pose at this step is unknown
        screws, posed = sorted((run.run_dir / "meshes").glob("*.stl")), False
    if not screws:
        run.notes.append("no dumps/screws_*.vtk and no meshes/*.stl: snapshot shows the particles only")
    name = f"{_slug(run.label)}_snapshot.png"
    render_snapshot(frame, run.out_dir / name, screws, time, posed)
    run.figures["snapshot"] = name


def _analyse_squeezes(run: RunAnalysis) -> None:
    """The squeeze ledger over the whole record (squeezes are counted from the run's start)."""
    run.squeezes = _source(run).squeeze_ledger()


def _sensor_flows(run: RunAnalysis) -> dict[str, Estimate]:
    return _source(run).sensor_flows(*_bounds(run))


def analyse_run(run_dir: Path, label: str, out_dir: Path, settings: Settings) -> RunAnalysis:
    run = RunAnalysis(label, Path(run_dir), out_dir)
    if not run.run_dir.is_dir():
        run.missing.append(("everything", f"{run.run_dir}: not a directory"))
        return run
    source = run.source = Run(run.run_dir)
    slug = _slug(label)
    _attempt(run, "run log", lambda: _read_log(run))
    _attempt(run, "run parameters", lambda: setattr(run, "parameters", source.parameters))
    _attempt(run, "zones", lambda: setattr(run, "zones", source.zones))
    decided = _attempt(run, "steady state", lambda: _decide_window(run, settings))
    if decided and run.massflow is not None and run.steady is not None:
        _attempt(run, "mean sensor flows", lambda: setattr(run, "sensor_flows", _sensor_flows(run)))
        run.figures["massflow"] = f"{slug}_massflow.png"
        figures.plot_massflow_series(out_dir / run.figures["massflow"], label, run.massflow, run.steady,
                                     run.sensor_flows)
    elif not settings.require_steady:
        run.window, run.transient = (-math.inf, math.inf), True
    read = _attempt(run, "residence records", lambda: setattr(run, "records", source.residence))
    if read and run.records is not None:
        run.notes.extend(run.records.issues)
        if _attempt(run, "RTD", lambda: _analyse_rtd(run)):
            run.figures["rtd"] = f"{slug}_rtd.png"
            figures.plot_rtd(out_dir / run.figures["rtd"], label, run.rtd_samples, run.rtd_stats)
    _attempt(run, "element profiles", lambda: _analyse_profile(run))
    _attempt(run, "dump files", lambda: _analyse_dumps(run, settings))
    if run.maps:
        run.figures["cross_sections"] = f"{slug}_cross_sections.png"
        figures.plot_cross_sections(out_dir / run.figures["cross_sections"], label, run.maps)
    if (run.run_dir / "squeezes.txt").is_file() and _attempt(run, "squeeze ledger", lambda: _analyse_squeezes(run)):
        run.figures["squeezes"] = f"{slug}_squeezes.png"
        figures.plot_squeezes_along_x(out_dir / run.figures["squeezes"], label, source.squeezes, source.zones)
    if run.plane_flows is not None and run.zones is not None:
        run.figures["plane_flows"] = f"{slug}_plane_flows.png"
        figures.plot_plane_flows(out_dir / run.figures["plane_flows"], label, run.plane_flows, run.zones)
    return run


# ---- several runs ---------------------------------------------------------------------------------

def build_report(run_dirs: list[Path], out_dir: Path, labels: list[str] | None = None,
                 settings: Settings = Settings()) -> Report:
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    labels = labels or run_labels(run_dirs)
    if len(labels) != len(run_dirs) or len(set(labels)) != len(labels):
        raise ValueError("give one distinct label per run directory")
    runs = [analyse_run(Path(d), label, out_dir, settings) for d, label in zip(run_dirs, labels)]
    report = Report(runs, [], {}, [], settings)

    with_profiles = [(run.label, run.profile) for run in runs if run.profile is not None]
    if with_profiles:
        report.figures["profiles"] = "profiles.png"
        figures.plot_profiles(out_dir / "profiles.png", with_profiles)
    else:
        report.missing.append(("element profiles figure", "no run has element profiles"))
    with_flows = [(run.label, run.sensor_flows) for run in runs if run.sensor_flows]
    if with_flows:
        report.figures["massflow_variants"] = "massflow_variants.png"
        figures.plot_massflow_variants(out_dir / "massflow_variants.png", with_flows)
    else:
        report.missing.append(("mass flow across runs", "no run has mean sensor flows"))
    if len(runs) > 1:  # every other run against the first: difference ± 95 % interval, significant or not
        reference = runs[0].estimates()
        for run in runs[1:]:
            for key, estimate in run.estimates().items():
                if key in reference:
                    report.differences.append((runs[0].label, run.label, *key, difference(reference[key], estimate)))
    with_rtd = [run for run in runs if run.rtd_samples]
    if len(runs) > 1:
        if len(with_rtd) > 1:
            first_rtd = with_rtd[0]
            for run in with_rtd[1:]:
                for scope in first_rtd.rtd_samples:
                    if scope in run.rtd_samples:
                        report.comparisons.append((first_rtd.label, run.label, compare_rtds(
                            first_rtd.rtd_samples[scope], run.rtd_samples[scope], scope)))
            report.figures["rtd_comparison"] = "rtd_comparison.png"
            figures.plot_rtd_comparison(out_dir / "rtd_comparison.png",
                                        [(run.label, run.rtd_samples) for run in with_rtd],
                                        {(label, c.scope): c for _, label, c in report.comparisons})
        else:
            report.missing.append(("RTD comparison", "fewer than two runs have an RTD"))
    write_outputs(report, out_dir)
    return report
