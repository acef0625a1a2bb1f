"""Files of the report: summary.json, CSV tables and report.md (Markdown sections are public so
that notebooks can show them one by one)."""
from __future__ import annotations

import csv
import json
import math
from dataclasses import asdict
from pathlib import Path

import numpy as np

from . import systematics
from .model import UNITS, Report, RunAnalysis
from .profiles import QUANTITIES
from .rtd import AGREEMENT_KS_DISTANCE, RTDStatistics, rtd_histogram
from .run_files import RTD_EXIT_REASONS
from .uncertainty import CONFIDENCE, MIN_INDEPENDENT, Estimate, format_interval

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
                     "transient_averages": run.transient,
                     "parameters": None if run.parameters is None else {
                         "source": run.parameters.source, "rpm": run.parameters.rpm, "rho_p": run.parameters.rho_p,
                         "d_mean": run.parameters.d_mean}}
    if run.steady is not None:
        summary["steady_state"] = {"reached": run.steady.reached, "start_time_s": _number(run.steady.start_time),
                                   "end_time_s": run.steady.end_time, "window_s": run.steady.window,
                                   "message": run.steady.message}
    if run.sensor_flows:
        summary["sensor_flow_kg_h"] = {name: e.as_dict() for name, e in run.sensor_flows.items()}
    if run.throughput is not None:
        summary["domain_throughput_kg_h"] = run.throughput.as_dict()
    if run.records is not None:
        summary["exit_reasons"] = run.records.reason_counts()
    summary["rtd"] = {scope: {k: _number(v) for k, v in asdict(s).items()} for scope, s in run.rtd_stats.items()}
    summary["mean_residence_time_s"] = {
        "from_records": {scope: e.as_dict() for scope, e in run.rtd_means.items()},
        "from_holdup_over_throughput": {scope: e.as_dict() for scope, e in run.holdup_residence.items()}}
    if run.profile is not None:
        summary["element_profiles"] = {
            "labels": run.profile.zones.labels, "types": list(run.profile.zones.kind),
            "blocks_averaged": run.profile.blocks, "records_averaged": run.profile.records,
            **{q: [e.as_dict() for e in estimates] for q, estimates in run.profile.estimates.items()}}
    summary["cross_sections"] = {kind: {"frames": m.frames, "axial_length_m": m.axial_length,
                                        "mean_solid_fraction": _number(m.mean),
                                        "max_solid_fraction": _number(float(np.nanmax(m.solid_fraction)))}
                                 for kind, m in run.maps.items()}
    if run.plane_flows is not None:
        summary["zone_boundary_mass_flow"] = {"x_m": _numbers(run.plane_flows.x),
                                              "flow_kg_h": _numbers(run.plane_flows.flow),
                                              "frames": run.plane_flows.frames, "duration_s": run.plane_flows.duration}
    return summary


ESTIMATE_COLUMNS = ["mean", "half_width_95", "independent_samples", "resolved", "drift", "detected_start"]


def _estimate_row(e: Estimate) -> list:
    return [_number(e.mean), _number(e.half_width), _number(round(e.independent_samples, 2)), e.resolved,
            e.drift, _number(e.detected_start)]


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
        "differences": [{"reference": ref, "run": label, "quantity": quantity, "unit": UNITS[quantity], "scope": scope,
                         **d.as_dict()} for ref, label, quantity, scope, d in report.differences],
        "comparisons": [{"reference": ref, "run": label, "scope": c.scope, "ks_distance": c.ks_distance,
                         "relative_mean_difference": c.mean_difference, "agree": c.agree,
                         "ks_p_value": c.ks_p_value}
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
    _write_csv(out_dir / "profiles.csv", ["run", "index", "element", "type", "quantity", *ESTIMATE_COLUMNS],
               [[run.label, i + 1, name, kind, q, *_estimate_row(estimates[i])]
                for run in report.runs if run.profile is not None
                for q, estimates in run.profile.estimates.items()
                for i, (name, kind) in enumerate(zip(run.profile.zones.labels, run.profile.zones.kind))])
    _write_csv(out_dir / "massflow.csv", ["run", "sensor", *ESTIMATE_COLUMNS],
               [[run.label, name, *_estimate_row(e)] for run in report.runs for name, e in run.sensor_flows.items()]
               + [[run.label, "domain (elements.txt)", *_estimate_row(run.throughput)] for run in report.runs
                  if run.throughput is not None])
    _write_csv(out_dir / "residence_means.csv", ["run", "method", "scope", *ESTIMATE_COLUMNS],
               [[run.label, "records", scope, *_estimate_row(e)] for run in report.runs
                for scope, e in run.rtd_means.items()]
               + [[run.label, "holdup/throughput", scope, *_estimate_row(e)] for run in report.runs
                  for scope, e in run.holdup_residence.items()])
    _write_csv(out_dir / "differences.csv", ["reference", "run", "quantity", "unit", "scope", "difference",
                                             "half_width_95", "relative", "significant", "inputs_resolved"],
               [[ref, label, quantity, UNITS[quantity], scope, _number(d.value), _number(d.half_width),
                 _number(d.relative), d.significant, d.inputs_resolved]
                for ref, label, quantity, scope, d in report.differences])
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


def _start(value: float | None) -> str:
    return "–" if value is None else f"{value:.4g} s"


def estimates_table(rows: list[tuple[str, Estimate]], unit: str, what: str = "quantity") -> list[str]:
    """Name, mean ± 95 % interval (or why not), independent samples, drift, chosen and detected start."""
    return _table([what, f"mean ± 95 % CI ({unit})", "independent samples", "stationary", "window from",
                   "stationary from (detected)"],
                  [[name, e.text(), f"{e.independent_samples:.1f}",
                    {True: "**drifting**", False: "yes", None: "too short to test"}[e.drift],
                    _start(e.chosen_start), _start(e.detected_start)] for name, e in rows])


def massflow_markdown(run: RunAnalysis, with_figures: bool = True) -> str:
    lines = []
    if run.parameters is not None:
        p = run.parameters
        lines += [f"**Run parameters** (from `{p.source}`): {p.rpm:g} rpm, particle density {p.rho_p:g} kg/m³, "
                  f"mean diameter {p.d_mean * 1e3:g} mm.", ""]
    if run.steady is not None:
        lines += [f"**Steady state:** {run.steady.message}.", "", *_figure(run, "massflow", "mass flow", with_figures)]
    if run.transient:
        lines += ["**Transient:** no steady window, so the averages of this run are over the whole record; "
                  "see the drift column and the detected start of stationarity.", ""]
    if run.sensor_flows or run.throughput is not None:
        rows = list(run.sensor_flows.items())
        if run.throughput is not None:
            rows.append(("domain flux Σ m v_x / L (elements.txt)", run.throughput))
        lines += ["**Mass flow:**", "", *estimates_table(rows, "kg/h", "sensor")]
    return "\n".join(lines)


def rtd_markdown(run: RunAnalysis, with_figures: bool = True) -> str:
    lines = []
    if run.records is not None:
        counts = run.records.reason_counts()
        lines += ["**Residence records:** " + ", ".join(f"{n} {reason}" for reason, n in counts.items())
                  + f" (only {' and '.join(RTD_EXIT_REASONS)} records exiting in the averaging window enter the RTD).",
                  ""]
    if run.rtd_means or run.holdup_residence:
        lines += ["### Mean residence time", ""]
        lines += estimates_table([(f"{scope} (records)", e) for scope, e in run.rtd_means.items()]
                                 + [(f"{scope} (hold-up / throughput)", e) for scope, e in run.holdup_residence.items()],
                                 "s", "scope (method)")
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
    measured = [q for q in QUANTITIES if q in p.estimates]
    lines = ["### Element profiles", "", f"{p.blocks} elements.txt blocks, {p.records} residence records; "
             f"mean ± {CONFIDENCE:.0%} interval, or why there is none.", ""]
    lines += _table(["element", "type", *(QUANTITIES[q] for q in measured)],
                    [[name, kind, *(_cell(p.estimates[q][i]) for q in measured)]
                     for i, (name, kind) in enumerate(zip(p.zones.labels, p.zones.kind))])
    return "\n".join(lines)


def _cell(e: Estimate) -> str:
    if not e.resolved:
        return "window too short" + (f" ({format_interval(e.mean, e.half_width)})" if math.isfinite(e.half_width) else "")
    return e.text()


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


def squeezes_markdown(run: RunAnalysis, with_figures: bool = True) -> str:
    if run.squeezes is None:
        return ""
    lines = ["### Squeezes", "", "```", run.squeezes.text(), "```", "",
             *_figure(run, "squeezes", "squeeze events along x", with_figures)]
    return "\n".join(lines) + "\n"


def comparison_markdown(report: Report) -> str:
    if not report.comparisons:
        return ""
    return "\n".join(["## RTD comparison", "", *_table(
        ["reference", "run", "scope", "KS distance D", "mean difference", "agree"],
        [[ref, label, c.scope, f"{c.ks_distance:.3f}", f"{c.mean_difference:+.1%}", "yes" if c.agree else "no"]
         for ref, label, c in report.comparisons])])


def differences_markdown(report: Report) -> str:
    """Each run against the first: difference ± 95 % interval; a number only where it is significant."""
    if not report.differences:
        return ""
    return "\n".join(["## Differences against the reference", "",
                      "run − reference ± 95 % interval; 'not resolved' when the interval includes zero, "
                      "'window too short' when either run has too few independent samples.", "", *_table(
                          ["reference", "run", "quantity", "scope", "difference", "significant"],
                          [[ref, label, f"{quantity} ({UNITS[quantity]})", scope, d.text(UNITS[quantity]),
                            "yes" if d.significant else "no"] for ref, label, quantity, scope, d in report.differences])])


def not_produced_markdown(report: Report) -> str:
    entries = report.not_produced
    lines = [f"- `{r}` — {part}: {reason}" for r, part, reason in entries] if entries else ["Everything was produced."]
    return "\n".join(["## Not produced", "", *lines]) + "\n"


def systematics_markdown(run: RunAnalysis) -> str:
    """The systematic errors the accuracy studies measured for the run's settings (tsg_analysis.systematics)."""
    head, *rows = systematics.lines_for(run.parameters)
    return "\n".join(["### Systematic errors", "", head[0].upper() + head[1:], "", *[f"- {r.strip()}" for r in rows], ""])


def markdown(report: Report) -> str:
    s = report.settings
    window = "one screw revolution of the run" if s.steady_window is None else f"{s.steady_window:g} s"
    lines = ["# TSG-DEM analysis report", "",
             f"Runs: {', '.join(f'`{run.label}`' for run in report.runs)}.", "",
             f"Every mean is given ± its {CONFIDENCE:.0%} confidence interval from its time series "
             "(statistical inefficiency, docs/statistics.md); with fewer than "
             f"{MIN_INDEPENDENT:g} independent samples the window is too short for a number and the interval "
             "is shown as indicative only. 'drifting': the two halves of the window differ beyond their "
             "intervals. The detected start of stationarity is shown beside the start of the window used.", "",
             f"Steady state: inlet (sensor_1) and outlet (last sensor) mean flows within {s.steady_tolerance:.0%} "
             f"in every window of {window} to the end of the record (at least 2 windows). "
             "RTDs use outlet/pass records that exit inside the steady window. "
             "Fits: tanks in series (N = t̄²/σ², and least squares on E(t) with t̄ fixed); axial dispersion "
             "closed–closed (Danckwerts, moments) and open–open (moments, and least squares on E(t)). "
             f"Two RTDs agree when the Kolmogorov–Smirnov distance D ≤ {AGREEMENT_KS_DISTANCE}. "
             f"Numbers in summary.json that are null are {NULL_MEANS}.", ""]
    for run in report.runs:
        lines += [f"## Run `{run.label}`", "", f"Directory: `{run.run_dir}`", "", log_markdown(run),
                  massflow_markdown(run), rtd_markdown(run), profile_markdown(run), systematics_markdown(run),
                  dumps_markdown(run), squeezes_markdown(run)]
        if run.notes:
            lines += ["**Input notes:**", "", *[f"- {n}" for n in run.notes], ""]
    lines += [differences_markdown(report), comparison_markdown(report)]
    for key, title in (("rtd_comparison", "RTDs of all runs"), ("profiles", "Element profiles of all runs"),
                       ("massflow_variants", "Mean sensor mass flow of all runs")):
        if key in report.figures:
            lines += [f"## {title}", "", f"![{title}]({report.figures[key]})", ""]
    lines += [not_produced_markdown(report)]
    return "\n".join(lines) + "\n"
