"""Matplotlib figures of the report (Agg backend: files only, no display needed)."""
from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from .cross_section import BORE_RADIUS, CENTRE_DISTANCE, SolidFractionMap
from .massflow import PlaneFlows, SteadyState
from .profiles import QUANTITIES, ElementProfile, aligned_positions
from .rtd import (
    RTDComparison,
    RTDStatistics,
    cumulative_distribution,
    histogram_edges,
    open_dispersion_density,
    rtd_histogram,
    tanks_in_series_density,
)
from .run_files import SQUEEZE_KINDS, MassFlowRecord, SqueezeRecords, Zones
from .uncertainty import Difference, Estimate

matplotlib.use("Agg")  # before the first figure: pyplot switches to it


def _save(fig: plt.Figure, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def plot_rtd(path: Path, label: str, samples: dict[str, np.ndarray], stats: dict[str, RTDStatistics]) -> Path:
    """E(t) with the least-squares fits, and F(t), for the total and each element type."""
    fig, axes = plt.subplots(2, len(samples), figsize=(4.2 * len(samples), 6.5), squeeze=False)
    for column, (scope, times) in enumerate(samples.items()):
        histogram = rtd_histogram(times)
        top, bottom = axes[0, column], axes[1, column]
        top.stairs(histogram.density, histogram.edges, color="k", label="simulation")
        s = stats[scope]
        if s.variance > 0:
            t = np.linspace(histogram.edges[0], histogram.edges[-1], 400)
            top.plot(t, tanks_in_series_density(t, s.mean, s.tanks_least_squares),
                     label=f"tanks in series, N = {s.tanks_least_squares:.3g}")
            top.plot(t, open_dispersion_density(t, s.mean, s.peclet_open_least_squares), "--",
                     label=f"open–open dispersion, Pe = {s.peclet_open_least_squares:.3g}")
        top.set_title(f"{label}: {scope} (n = {s.count}, t̄ = {s.mean:.3g} s)")
        top.set_xlabel("t (s)")
        top.set_ylabel("E(t) (1/s)")
        top.legend(fontsize=7)
        ordered, fraction = cumulative_distribution(times)
        bottom.step(ordered, fraction, where="post", color="k")
        bottom.set_xlabel("t (s)")
        bottom.set_ylabel("F(t)")
        bottom.grid(alpha=0.3)
    return _save(fig, path)


def plot_rtd_comparison(path: Path, runs: list[tuple[str, dict[str, np.ndarray]]],
                        comparisons: dict[tuple[str, str], RTDComparison]) -> Path:
    """E(t) of every run on common bins, one panel per scope that a run has times for (seed Fig. 8)."""
    scopes = list(dict.fromkeys(scope for _, samples in runs for scope, times in samples.items() if len(times) >= 2))
    if not scopes:
        return _nothing_to_plot(path, "no scope with complete passes in any run")
    fig, axes = plt.subplots(1, len(scopes), figsize=(4.5 * len(scopes), 3.8), squeeze=False)
    for ax, scope in zip(axes[0], scopes):
        having = [(label, samples) for label, samples in runs if len(samples.get(scope, ())) >= 2]
        edges = histogram_edges(np.concatenate([samples[scope] for _, samples in having]))
        for label, samples in having:
            histogram = rtd_histogram(samples[scope], edges)
            comparison = comparisons.get((label, scope))
            suffix = "" if comparison is None else f" (KS D = {comparison.ks_distance:.3f})"
            ax.stairs(histogram.density, edges, label=label + suffix)
        ax.set_title(scope)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("E(t) (1/s)")
        ax.legend(fontsize=7)
    return _save(fig, path)


def _nothing_to_plot(path: Path, message: str) -> Path:
    """A figure that says why it is empty (e.g. no run reached steady state), instead of failing."""
    fig, ax = plt.subplots(figsize=(6, 2))
    ax.text(0.5, 0.5, message, ha="center", va="center", wrap=True)
    ax.set_axis_off()
    return _save(fig, path)


def plot_profiles(path: Path, profiles: list[tuple[str, ElementProfile]]) -> Path:
    """Solid fraction, residence time, velocity magnitude and longitudinal velocity per element
    for one run or a family of runs (seed Figs. 9, 10, 12–16); bars: 95 % intervals; hollow points:
    too few independent samples, the bar is indicative only."""
    if not profiles:
        return _nothing_to_plot(path, "no run has element profiles (see the report's 'Not produced')")
    positions = aligned_positions([profile.zones for _, profile in profiles])
    tick_labels: dict[int, str] = {}
    for (_, profile), where in zip(profiles, positions):
        for position, name in zip(where, profile.zones.labels):
            tick_labels.setdefault(int(position), name)
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    for ax, (quantity, axis_label) in zip(axes.flat, QUANTITIES.items()):
        for (label, profile), where in zip(profiles, positions):
            estimates = profile.estimates.get(quantity)
            if estimates is None:
                continue
            resolved = np.array([e.resolved for e in estimates])
            errors = np.array([e.half_width for e in estimates])
            line, = ax.plot(where, profile.values[quantity], "-", label=label)
            ax.errorbar(where[resolved], profile.values[quantity][resolved], yerr=errors[resolved], fmt="o",
                        color=line.get_color(), capsize=3)
            ax.errorbar(where[~resolved], profile.values[quantity][~resolved], yerr=errors[~resolved], fmt="o",
                        mfc="white", color=line.get_color(), alpha=0.6, capsize=3, ls="none",
                        label=f"{label}: window too short (indicative interval)" if (~resolved).any() else None)
        if not any(quantity in profile.estimates for _, profile in profiles):
            ax.text(0.5, 0.5, "not measured (see the report)", transform=ax.transAxes, ha="center", color="grey")
        ax.set_ylabel(axis_label)
        ax.grid(alpha=0.3)
    first_zones, first_positions = profiles[0][1].zones, positions[0]
    for ax in axes.flat:
        for kind, position in zip(first_zones.kind, first_positions):
            if kind != "conveying":  # shade the mixing elements as the paper's figures do
                ax.axvspan(position - 0.5, position + 0.5, color="tab:orange" if kind == "kneading" else "tab:red",
                           alpha=0.08, lw=0)
    ticks = sorted(tick_labels)
    for ax in axes[1]:
        ax.set_xticks(ticks, [tick_labels[t] for t in ticks], rotation=90 if len(ticks) > 16 else 0)
        ax.set_xlabel("element")
    axes[0, 0].legend(fontsize=8)
    return _save(fig, path)


def plot_massflow_series(path: Path, label: str, record: MassFlowRecord, steady: SteadyState,
                         flows: dict[str, Estimate] | None = None) -> Path:
    """Sensor traces, window means, the steady window and, per sensor, the detected start of
    stationarity (dashed) and the mean ± 95 % interval over the window used (band)."""
    fig, ax = plt.subplots(figsize=(9, 4))
    for k, name in enumerate(record.sensor_names):
        few = len(record.time) < 200  # a short record: show every sample
        line, = ax.plot(record.time, record.flow[:, k], lw=1.0 if few else 0.5, alpha=0.9 if few else 0.35,
                        marker="o" if few else None, ms=3, label=f"{name} samples" if few else None)
        if len(steady.window_starts):
            ax.step(np.append(steady.window_starts, steady.end_time),
                    np.append(steady.window_means[:, k], steady.window_means[-1, k]),
                    where="post", color=line.get_color(), lw=2, label=f"{name} ({steady.window:g} s means)")
        estimate = (flows or {}).get(name)
        if estimate is not None and np.isfinite(estimate.half_width):
            ax.axhspan(estimate.mean - estimate.half_width, estimate.mean + estimate.half_width,
                       color=line.get_color(), alpha=0.12, label=f"{name}: {estimate.text('kg/h')}")
        if estimate is not None and estimate.detected_start is not None:
            ax.axvline(estimate.detected_start, color=line.get_color(), ls="--", lw=1,
                       label=f"{name} stationary from {estimate.detected_start:.3g} s (detected)")
    if steady.start_time is not None:  # reached
        ax.axvspan(steady.start_time, steady.end_time, color="tab:green", alpha=0.1, label="steady window")
    ax.set_title(f"{label}: {'steady' if steady.reached else 'NOT steady'}", fontsize=10)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("mass flow (kg/h)")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    return _save(fig, path)


def plot_massflow_variants(path: Path, rows: list[tuple[str, dict[str, Estimate]]]) -> Path:
    """Mean sensor flows for each run (seed Fig. 18); bars: 95 % intervals (hollow: window too short)."""
    if not rows:
        return _nothing_to_plot(path, "no run has sensor flows (see the report's 'Not produced')")
    fig, ax = plt.subplots(figsize=(max(5.0, 1.2 * len(rows) + 2), 4))
    names = list(dict.fromkeys(name for _, flows in rows for name in flows))
    for k, name in enumerate(names):
        offset = (k - (len(names) - 1) / 2) * 0.12
        points = [(i + offset, flows[name]) for i, (_, flows) in enumerate(rows) if name in flows]
        ax.errorbar([x for x, _ in points], [e.mean for _, e in points], yerr=[e.half_width for _, e in points],
                    fmt="o", capsize=3, label=name, mfc="none" if not all(e.resolved for _, e in points) else None)
    ax.set_xticks(range(len(rows)), [label for label, _ in rows], rotation=30, ha="right")
    ax.set_xlim(-0.5, len(rows) - 0.5)
    ax.set_ylabel("mean mass flow (kg/h)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return _save(fig, path)


def _bore_outline(ax: plt.Axes, centre_distance: float, bore_radius: float) -> None:
    """Outline of the twin bore in mm: each circle without the arc inside the other one."""
    half = centre_distance / 2
    cut = np.arccos(half / bore_radius)  # angle where the circles meet, seen from each centre
    for centre, start in ((-half, cut), (half, np.pi + cut)):
        angle = np.linspace(start, start + 2 * np.pi - 2 * cut, 200)
        ax.plot(1e3 * (centre + bore_radius * np.cos(angle)), 1e3 * bore_radius * np.sin(angle), "k", lw=1)
        ax.plot(1e3 * centre, 0, "k+")


def plot_cross_sections(path: Path, label: str, maps: dict[str, SolidFractionMap],
                        centre_distance: float = CENTRE_DISTANCE, bore_radius: float = BORE_RADIUS) -> Path:
    fig, axes = plt.subplots(1, len(maps), figsize=(6.2 * len(maps), 3.6), squeeze=False)
    top = max(float(np.nanmax(m.solid_fraction)) for m in maps.values()) or 1.0
    for ax, (kind, m) in zip(axes[0], maps.items()):
        image = ax.imshow(m.solid_fraction.T, origin="lower", cmap="viridis", vmin=0, vmax=top,
                          extent=1e3 * np.array([m.y_edges[0], m.y_edges[-1], m.z_edges[0], m.z_edges[-1]]))
        _bore_outline(ax, centre_distance, bore_radius)
        ax.set_title(f"{label}: {kind} ({m.frames} frames, {1e3 * m.axial_length:.4g} mm)", fontsize=9)
        ax.set_xlabel("y (mm)")
        ax.set_ylabel("z (mm)")
        ax.set_aspect("equal")
        fig.colorbar(image, ax=ax, label="solid fraction (-)", shrink=0.85)
    return _save(fig, path)


def plot_plane_flows(path: Path, label: str, flows: PlaneFlows, zones: Zones) -> Path:
    """Net mass flow through the zone boundaries, counted from the dumps."""
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(1e3 * flows.x, flows.flow, "o-")
    for kind, start, end in zip(zones.kind, zones.x_start, zones.x_end):
        if kind != "conveying":
            ax.axvspan(1e3 * start, 1e3 * end, color="tab:orange" if kind == "kneading" else "tab:red", alpha=0.1, lw=0)
    ax.set_title(f"{label}: net mass flow through zone boundaries from dumps "
                 f"({flows.frames} frames, {flows.duration:.3g} s)", fontsize=9)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("mass flow (kg/h)")
    ax.grid(alpha=0.3)
    return _save(fig, path)


def plot_paper_mass_flow(path: Path, rows: list[tuple[str, Difference | None, tuple[float, float] | None]],
                         reference_paper: tuple[float, float]) -> Path:
    """Each variant's mass flow relative to the reference: ours (difference ± 95 % interval; hollow:
    not significant) beside the paper's range (seed Fig. 18, relative to its reference's 14.5 kg/h)."""
    if not rows:
        return _nothing_to_plot(path, "no variant has a finished run")
    fig, ax = plt.subplots(figsize=(max(5.0, 1.1 * len(rows) + 2), 4))
    paper_ref = 0.5 * (reference_paper[0] + reference_paper[1])
    labels = {"paper": "paper (Fig. 18)", "ours": "ours (95 % interval; hollow: not significant)"}
    for i, (_, ours, paper) in enumerate(rows):
        if paper is not None:
            ax.add_patch(plt.Rectangle((i - 0.3, paper[0] / paper_ref - 1), 0.25,
                                       max((paper[1] - paper[0]) / paper_ref, 0.005), color="tab:orange", alpha=0.6,
                                       label=labels.pop("paper", None)))
        if ours is not None and math.isfinite(ours.relative) and ours.value != 0:
            scale = ours.relative / ours.value  # 1 / the reference's mean
            ax.errorbar([i + 0.15], [ours.relative], yerr=[abs(ours.half_width * scale)], fmt="o", capsize=3,
                        color="tab:blue", mfc="tab:blue" if ours.significant else "none", label=labels.pop("ours", None))
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xticks(range(len(rows)), [label for label, _, _ in rows], rotation=30, ha="right")
    ax.set_xlim(-0.6, len(rows) - 0.4)
    ax.set_ylabel("mass flow relative to the reference")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return _save(fig, path)


def plot_element_panels(path: Path, rows: Sequence, quantities: Sequence[str]) -> Path:
    """Per-element values of each setting of a sweep (analogues of the seed paper's Figs. 13–16):
    one panel per quantity, one line per setting, bars: 95 % intervals (hollow: not resolved).
    `rows`: summary.ComparisonRow (each holds the reference's and the variant's estimate)."""
    element_rows = [r for r in rows if r.quantity in quantities and r.scope[:1] in ("C", "K") and r.scope[1:].isdigit()]
    if not element_rows:
        return _nothing_to_plot(path, "no per-element comparison")
    scopes = list(dict.fromkeys(r.scope for r in element_rows))
    settings = ["reference", *dict.fromkeys(r.variant for r in element_rows)]
    fig, axes = plt.subplots(1, len(quantities), figsize=(5.5 * len(quantities), 4.2), squeeze=False)
    for ax, quantity in zip(axes[0], quantities):
        mine = [r for r in element_rows if r.quantity == quantity]
        for k, setting in enumerate(settings):
            estimates = {r.scope: (r.reference if setting == "reference" else r.value) for r in mine
                         if setting == "reference" or r.variant == setting}
            xs = [i + (k - (len(settings) - 1) / 2) * 0.06 for i, s in enumerate(scopes) if s in estimates]
            values = [estimates[s] for s in scopes if s in estimates]
            if not values:
                continue
            ax.errorbar(xs, [e.mean for e in values], yerr=[e.half_width if math.isfinite(e.half_width) else 0 for e in values],
                        fmt="-o", ms=4, capsize=2, label=setting, lw=1.2 if setting == "reference" else 0.8,
                        mfc="none" if not all(e.resolved for e in values) else None)
        ax.set_xticks(range(len(scopes)), scopes)
        ax.set_title(quantity)
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    return _save(fig, path)


def plot_domain_elements(path: Path, rows: Sequence, quantities: Sequence[str], units: dict[str, str]) -> Path:
    """The periodic sub-domain against the full granulator element by element (seed Fig. 9): one
    panel per quantity, bars: 95 % intervals (hollow: not resolved). `rows`: domains.DomainRow."""
    scopes = list(dict.fromkeys(r.scope for r in rows if r.scope[:1] in ("C", "K") and r.scope[1:].isdigit()))
    fig, axes = plt.subplots(1, len(quantities), figsize=(4.5 * len(quantities), 3.8), squeeze=False)
    for ax, quantity in zip(axes[0], quantities):
        mine = {r.scope: r for r in rows if r.quantity == quantity and r.scope in scopes}
        for k, side in enumerate(("full", "periodic")):
            values = [getattr(mine[s], side) for s in scopes if s in mine]
            xs = [i + (k - 0.5) * 0.12 for i, s in enumerate(scopes) if s in mine]
            ax.errorbar(xs, [e.mean for e in values],
                        yerr=[e.half_width if math.isfinite(e.half_width) else 0 for e in values],
                        fmt="-o", ms=4, capsize=2, lw=1, label=side,
                        mfc="none" if not all(e.resolved for e in values) else None)
        ax.set_xticks(range(len(scopes)), scopes)
        ax.set_title(f"{quantity} ({units[quantity]})", fontsize=10)
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, path)


def plot_squeezes_along_x(path: Path, label: str, records: SqueezeRecords, zones: Zones) -> Path:
    """Squeeze events along the axis (the position of each event's deepest overlap), stacked by kind,
    with the element boundaries."""
    fig, ax = plt.subplots(figsize=(9, 3.5))
    x = records["x"] * 1e3
    edges = np.linspace(float(zones.x_start[0]) * 1e3, float(zones.x_end[-1]) * 1e3, 97)
    kinds = records["kind"].astype(int)
    ax.hist([x[kinds == k] for k in range(len(SQUEEZE_KINDS))], bins=list(edges), stacked=True,
            label=list(SQUEEZE_KINDS))
    for boundary, name in zip(zones.x_start * 1e3, zones.labels):
        ax.axvline(boundary, color="0.6", lw=0.6)
        ax.text(boundary, 1.0, f" {name}", transform=ax.get_xaxis_transform(), fontsize=7, va="top")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("squeeze events")
    ax.set_title(f"{label}: {len(records)} squeeze events along x", fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
