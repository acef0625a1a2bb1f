"""Files of the report: summary.json, CSV tables and report.md (Markdown sections are public so
that notebooks can show them one by one)."""
from __future__ import annotations

import csv
import json
import math
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .profiles import QUANTITIES
from .rtd import AGREEMENT_KS_DISTANCE, RTDStatistics, rtd_histogram
from .run_files import RTD_EXIT_REASONS

if TYPE_CHECKING:  # report.py imports this module to write its files
    from .report import Report, RunAnalysis

NULL_MEANS = "infinite or undefined (e.g. the tanks-in-series N of a plug flow)"


# ---- JSON and CSV ---------------------------------------------------------------------------------

def _number(value: float | int | None) -> float | int | None:
    """JSON has no inf/nan: they become null (NULL_MEANS says so in the file)."""
    if value is None:
        return None
    value = value.item() if isinstance(value, np.generic) else value
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _numbers(values: np.ndarray) -> list:
    return [_number(float(v)) for v in np.asarray(values, dtype=np.float64)]


def run_summary(run: RunAnalysis) -> dict:
    summary: dict = {"label": run.label, "run_dir": str(run.run_dir), "figures": run.figures, "notes": run.notes,
                     "not_produced": [{"part": p, "reason": r} for p, r in run.missing], "log": run.log_summary,
                     "transient_averages": run.transient}
    if run.steady is not None:
        summary["steady_state"] = {"reached": run.steady.reached, "start_time_s": _number(run.steady.start_time),
                                   "end_time_s": run.steady.end_time, "message": run.steady.message}
    if run.sensor_means is not None:
        summary["sensor_mean_kg_h"] = dict(zip(run.massflow.sensor_names, _numbers(run.sensor_means[0])))
        summary["sensor_fluctuation_kg_h"] = dict(zip(run.massflow.sensor_names, _numbers(run.sensor_means[1])))
    if run.records is not None:
        summary["exit_reasons"] = run.records.reason_counts()
    summary["rtd"] = {scope: {k: _number(v) for k, v in asdict(s).items()} for scope, s in run.rtd_stats.items()}
    if run.profile is not None:
        summary["element_profiles"] = {
            "labels": run.profile.zones.labels, "types": list(run.profile.zones.kind),
            "blocks_averaged": run.profile.blocks, "records_averaged": run.profile.records,
            **{q: _numbers(v) for q, v in run.profile.values.items()}}
    summary["cross_sections"] = {kind: {"frames": m.frames, "axial_length_m": m.axial_length,
                                        "mean_solid_fraction": _number(m.mean),
                                        "max_solid_fraction": _number(float(np.nanmax(m.solid_fraction)))}
                                 for kind, m in run.maps.items()}
    if run.plane_flows is not None:
        summary["zone_boundary_mass_flow"] = {"x_m": _numbers(run.plane_flows.x),
                                              "flow_kg_h": _numbers(run.plane_flows.flow),
                                              "frames": run.plane_flows.frames, "duration_s": run.plane_flows.duration}
    return summary


def _write_csv(path: Path, header: list[str], rows: list[list]) -> None:
    with open(path, "w", newline="", encoding="utf-8") as stream:
        writer = csv.writer(stream)
        writer.writerow(header)
        writer.writerows([["" if v is None else v for v in row] for row in rows])


def write_outputs(report: Report, out_dir: Path) -> None:
    summary = {
        "settings": asdict(report.settings),
        "rtd_agreement_ks_distance": AGREEMENT_KS_DISTANCE,
        "runs": [run_summary(run) for run in report.runs],
        "comparisons": [{"reference": ref, "run": label, "scope": c.scope, "ks_distance": c.ks_distance,
                         "relative_mean_difference": c.mean_difference, "agree": c.agree}
                        for ref, label, c in report.comparisons],
        "figures": report.figures,
        "not_produced": [{"run": r, "part": p, "reason": why} for r, p, why in report.not_produced],
        "null_means": NULL_MEANS,
    }
    (out_dir / "summary.json").write_text(json.dumps(summary, indent=2, allow_nan=False), encoding="utf-8")
    stat_names = list(RTDStatistics.__dataclass_fields__)
    _write_csv(out_dir / "rtd_statistics.csv", ["run", "scope", *stat_names],
               [[run.label, scope, *(_number(getattr(s, n)) for n in stat_names)]
                for run in report.runs for scope, s in run.rtd_stats.items()])
    curves = []
    for run in report.runs:
        for scope, times in run.rtd_samples.items():
            histogram = rtd_histogram(times)
            curves += [[run.label, scope, a, b, e] for a, b, e in
                       zip(histogram.edges[:-1], histogram.edges[1:], histogram.density)]
    _write_csv(out_dir / "rtd_curves.csv", ["run", "scope", "t_low_s", "t_high_s", "E_per_s"], curves)
    _write_csv(out_dir / "profiles.csv", ["run", "index", "element", "type", *QUANTITIES],
               [[run.label, i + 1, name, kind, *(_number(float(run.profile.values[q][i])) for q in QUANTITIES)]
                for run in report.runs if run.profile is not None
                for i, (name, kind) in enumerate(zip(run.profile.zones.labels, run.profile.zones.kind))])
    _write_csv(out_dir / "massflow.csv", ["run", "sensor", "mean_kg_h", "fluctuation_kg_h"],
               [[run.label, name, _number(m), _number(s)] for run in report.runs if run.sensor_means is not None
                for name, m, s in zip(run.massflow.sensor_names, *run.sensor_means)])
    _write_csv(out_dir / "rtd_comparison.csv",
               ["reference", "run", "scope", "ks_distance", "relative_mean_difference", "agree"],
               [[ref, label, c.scope, c.ks_distance, c.mean_difference, c.agree] for ref, label, c in report.comparisons])
    (out_dir / "report.md").write_text(markdown(report), encoding="utf-8")


# ---- Markdown -------------------------------------------------------------------------------------

def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header),
            *["| " + " | ".join(row) + " |" for row in rows], ""]


def _fmt(value: float | None, digits: int = 4) -> str:
    if value is None or math.isnan(value):
        return "–"
    if math.isinf(value):
        return "∞"
    return f"{value:.{digits}g}"


def _figure(run: RunAnalysis, key: str, title: str, with_figures: bool) -> list[str]:
    return [f"![{title}]({run.figures[key]})", ""] if with_figures and key in run.figures else []


def log_markdown(run: RunAnalysis) -> str:
    if run.log_summary is None:
        return ""
    log = run.log_summary
    lines = [f"**Log:** last step {log['last_step']}, {log['particles']} particles, "
             f"{sum(log['warnings'].values())} warnings, {len(log['errors'])} errors.", ""]
    lines += [f"- warning ×{n}: {w}" for w, n in log["warnings"].items()]
    lines += [f"- **error**: {e}" for e in log["errors"]]
    return "\n".join(lines) + "\n"


def massflow_markdown(run: RunAnalysis, with_figures: bool = True) -> str:
    lines = []
    if run.steady is not None:
        lines += [f"**Steady state:** {run.steady.message}.", "", *_figure(run, "massflow", "mass flow", with_figures)]
    if run.transient:
        lines += ["**Transient:** the averages of this run are over the whole record (--allow-transient).", ""]
    if run.sensor_means is not None:
        lines += _table(["sensor", "mean (kg/h)", "fluctuation (kg/h)"],
                        [[n, _fmt(m), _fmt(s)] for n, m, s in zip(run.massflow.sensor_names, *run.sensor_means)])
    return "\n".join(lines)


def rtd_markdown(run: RunAnalysis, with_figures: bool = True) -> str:
    lines = []
    if run.records is not None:
        counts = run.records.reason_counts()
        lines += ["**Residence records:** " + ", ".join(f"{n} {reason}" for reason, n in counts.items())
                  + f" (only {' and '.join(RTD_EXIT_REASONS)} records exiting in the averaging window enter the RTD).",
                  ""]
    if run.rtd_stats:
        lines += ["### Residence-time distribution", ""]
        lines += _table(["scope", "n", "mean (s)", "variance (s²)", "σ²/t̄²", "N moments", "N least squares",
                         "Pe closed–closed (moments)", "Pe open–open (moments)", "Pe open–open (least squares)"],
                        [[scope, str(s.count), _fmt(s.mean), _fmt(s.variance), _fmt(s.normalised_variance),
                          _fmt(s.tanks_moments), _fmt(s.tanks_least_squares), _fmt(s.peclet_closed_moments),
                          _fmt(s.peclet_open_moments), _fmt(s.peclet_open_least_squares)]
                         for scope, s in run.rtd_stats.items()])
        lines += _figure(run, "rtd", "RTD", with_figures)
    return "\n".join(lines)


def profile_markdown(run: RunAnalysis) -> str:
    if run.profile is None:
        return ""
    p = run.profile
    lines = ["### Element profiles", "", f"{p.blocks} elements.txt blocks, {p.records} residence records.", ""]
    lines += _table(["element", "type", *QUANTITIES],
                    [[name, kind, *(_fmt(float(p.values[q][i])) for q in QUANTITIES)]
                     for i, (name, kind) in enumerate(zip(p.zones.labels, p.zones.kind))])
    return "\n".join(lines)


def dumps_markdown(run: RunAnalysis, with_figures: bool = True) -> str:
    lines = []
    if run.maps:
        lines += ["### Cross-section solid fraction", ""]
        lines += _table(["type", "frames", "axial length (mm)", "mean", "max"],
                        [[k, str(m.frames), _fmt(1e3 * m.axial_length), _fmt(m.mean),
                          _fmt(float(np.nanmax(m.solid_fraction)))] for k, m in run.maps.items()])
        lines += _figure(run, "cross_sections", "cross sections", with_figures)
    if run.plane_flows is not None:
        lines += ["### Mass flow through zone boundaries (from dumps)", "",
                  f"{run.plane_flows.frames} frames over {run.plane_flows.duration:.4g} s.", "",
                  *_figure(run, "plane_flows", "zone boundary flows", with_figures)]
    if "snapshot" in run.figures:
        lines += ["### Snapshot", "", *_figure(run, "snapshot", "snapshot", with_figures)]
    return "\n".join(lines)


def comparison_markdown(report: Report) -> str:
    if not report.comparisons:
        return ""
    return "\n".join(["## RTD comparison", "", *_table(
        ["reference", "run", "scope", "KS distance D", "mean difference", "agree"],
        [[ref, label, c.scope, f"{c.ks_distance:.3f}", f"{c.mean_difference:+.1%}", "yes" if c.agree else "no"]
         for ref, label, c in report.comparisons])])


def not_produced_markdown(report: Report) -> str:
    entries = report.not_produced
    lines = [f"- `{r}` — {part}: {reason}" for r, part, reason in entries] if entries else ["Everything was produced."]
    return "\n".join(["## Not produced", "", *lines]) + "\n"


def markdown(report: Report) -> str:
    s = report.settings
    lines = ["# TSG-DEM analysis report", "",
             f"Runs: {', '.join(f'`{run.label}`' for run in report.runs)}.", "",
             f"Steady state: inlet (sensor_1) and outlet (last sensor) mean flows within {s.steady_tolerance:.0%} "
             f"in every {s.steady_window:g} s window to the end of the record (at least 2 windows). "
             "RTDs use outlet/pass records that exit inside the steady window. "
             "Fits: tanks in series (N = t̄²/σ², and least squares on E(t) with t̄ fixed); axial dispersion "
             "closed–closed (Danckwerts, moments) and open–open (moments, and least squares on E(t)). "
             f"Two RTDs agree when the Kolmogorov–Smirnov distance D ≤ {AGREEMENT_KS_DISTANCE}. "
             f"Numbers in summary.json that are null are {NULL_MEANS}.", ""]
    for run in report.runs:
        lines += [f"## Run `{run.label}`", "", f"Directory: `{run.run_dir}`", "", log_markdown(run),
                  massflow_markdown(run), rtd_markdown(run), profile_markdown(run), dumps_markdown(run)]
        if run.notes:
            lines += ["**Input notes:**", "", *[f"- {n}" for n in run.notes], ""]
    lines += [comparison_markdown(report)]
    for key, title in (("rtd_comparison", "RTDs of all runs"), ("profiles", "Element profiles of all runs"),
                       ("massflow_variants", "Mean sensor mass flow of all runs")):
        if key in report.figures:
            lines += [f"## {title}", "", f"![{title}]({report.figures[key]})", ""]
    lines += [not_produced_markdown(report)]
    return "\n".join(lines) + "\n"
