"""The short summary of a run (what the case runner prints) and sweep tables, every number with its
95 % confidence interval.

`summarise(run)` (a run.Run) averages over the whole sampling record the run wrote (the case inputs start
their outputs after the start-up), or over its part from `start` s on (a steady window chosen after
the run), and reports the detected start of stationarity beside it.
`summary_table(run)` is the text the runner prints. `compare_runs(reference, variants)` gives,
for each variant (one or several replica run directories), the difference of every quantity against
the reference with its interval, marked significant or not; `sweep_markdown` / `write_sweep_csv`
write it.
"""
from __future__ import annotations

import csv
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from . import systematics
from .liggghts_log import parse_thermo
from .model import AXIAL_VELOCITY, MASS_FLOW, RESIDENCE_HOLDUP, RESIDENCE_RECORDS, SOLID_FRACTION, SPEED, UNITS, Key
from .parameters import RunParameters
from .run import Run
from .run_files import AnalysisInputError
from .uncertainty import Difference, Estimate, combine_replicas, difference


@dataclass(frozen=True)
class SummaryRow:
    quantity: str  # one of UNITS
    scope: str  # sensor, element type, element label
    estimate: Estimate

    @property
    def unit(self) -> str:
        return UNITS[self.quantity]


@dataclass
class RunSummary:
    run_dir: Path
    parameters: RunParameters | None
    rows: list[SummaryRow] = field(default_factory=list)
    complete_records: int = 0
    not_available: list[tuple[str, str]] = field(default_factory=list)  # (quantity, reason)

    def get(self, quantity: str, scope: str) -> Estimate | None:
        return next((r.estimate for r in self.rows if r.quantity == quantity and r.scope == scope), None)


def _part(summary: RunSummary, quantity: str, action: Callable[[], None]) -> None:
    try:
        action()
    except AnalysisInputError as problem:
        summary.not_available.append((quantity, str(problem)))


def summarise(run: Run, start: float | None = None, end: float | None = None) -> RunSummary:
    """Every quantity of the run's summary ± 95 % interval, over the whole sampling record or over
    its part from `start` s on, up to `end` s (the window rule of Run)."""
    summary = RunSummary(run.path, None)
    _part(summary, "run parameters", lambda: setattr(summary, "parameters", run.parameters))
    run.zones  # every per-element number is named by zones.txt: without it there is no summary

    def rows(found: dict[Key, Estimate]) -> None:
        summary.rows += [SummaryRow(quantity, scope, e) for (quantity, scope), e in found.items() if quantity in UNITS]

    def records() -> None:
        summary.complete_records = int(run.records(start, end).sum())
        rows({(RESIDENCE_RECORDS, scope): e for scope, e in run.residence_means(start, end).items()})

    _part(summary, MASS_FLOW, lambda: rows({(MASS_FLOW, name): e for name, e in run.sensor_flows(start, end).items()}))
    _part(summary, RESIDENCE_RECORDS, records)
    _part(summary, "element statistics", lambda: rows(run.element_keys(start, end)))
    return summary


def _start(value: float | None) -> str:
    return "-" if value is None else f"{value:.4g}"


def thermo_largest(run: Run, prefix: str) -> float | None:
    """The largest value of the log's thermo columns whose names start with `prefix`, over every
    block of every segment's log (Run.segment_logs); None without such a column (or without log.lammps)."""
    try:
        logs = run.segment_logs
    except AnalysisInputError:
        return None
    values = [v.max() for log in logs for b in parse_thermo(log) for name, v in b.items()
              if name.startswith(prefix) and v.size]
    return float(max(values)) if values else None


def contact_health(run: Run) -> str | None:
    """What the guards of fix check/contact saw over the run, from its thermo columns
    (cases/include/thermo.in): squeeze releases counted (`fast`, cumulative), the largest wall
    overlap/R (`pg_*`) and particle speed, and the wall crossings the squeeze ledger counted
    (`crossed`, cumulative: a particle centre behind a screw or barrel surface); None when the log
    has none of them."""
    fast, wall, speed, crossed = (thermo_largest(run, prefix) for prefix in ("fast", "pg_", "speed", "crossed"))
    if fast is None and wall is None:
        return None
    parts = [f"{int(fast)} squeeze releases (particles faster than guard_fast_speed, counted)"] if fast is not None else []
    parts += [f"largest wall overlap/R {wall:.3g}"] if wall is not None else []
    parts += [f"largest speed {speed:.3g} m/s"] if speed is not None else []
    if crossed is not None:
        parts += [f"{int(crossed)} wall crossings" + (" (particle centres behind a screw or barrel surface: "
                                                     "log.lammps names each)" if crossed > 0 else "")]
    return "contacts over the run: " + ", ".join(parts)


def squeeze_lines(run: Run) -> list[str]:
    """The run's squeeze ledger (squeezes.txt), or why there is none; nothing for a run without the
    ledger."""
    if not (run.path / "squeezes.txt").is_file():
        return []
    try:
        return run.squeeze_ledger().text().splitlines()
    except AnalysisInputError as why:
        return [f"squeezes: none ({why})"]


def combine_summaries(summaries: Sequence[RunSummary]) -> RunSummary:
    """Replicas (runs that differ only in the fill seed) combined quantity by quantity
    (uncertainty.combine_replicas); a quantity only where every replica has it."""
    if not summaries:
        raise ValueError("no run summaries")
    if len(summaries) == 1:
        return summaries[0]
    first = summaries[0]
    combined = RunSummary(first.run_dir, first.parameters, complete_records=sum(s.complete_records for s in summaries))
    for row in first.rows:
        estimates = [s.get(row.quantity, row.scope) for s in summaries]
        if all(e is not None for e in estimates):
            combined.rows.append(SummaryRow(row.quantity, row.scope, combine_replicas(estimates)))  # type: ignore[arg-type]
    combined.not_available = list(dict.fromkeys(why for s in summaries for why in s.not_available))
    return combined


def summary_table(runs: Run | Sequence[Run]) -> str:
    """The runner's summary: one line per quantity, mean ± 95 % interval or why there is none. Several
    runs: replicas, combined (combine_summaries), after each replica's contact and squeeze lines."""
    runs = [runs] if isinstance(runs, Run) else list(runs)
    summary = combine_summaries([summarise(run) for run in runs])
    lines = []
    if summary.parameters is not None:
        p = summary.parameters
        lines.append(f"parameters ({p.source}): {p.rpm:g} rpm, rho_p {p.rho_p:g} kg/m3, d_mean {p.d_mean:g} m")
    for run in runs:
        own = [line for line in [contact_health(run), *squeeze_lines(run)] if line is not None]
        lines += [f"{run.path.name}: {line}" for line in own] if len(runs) > 1 else own
    window = "over the sampling window" if len(runs) == 1 else \
        f"over the sampling windows of {len(runs)} replicas combined ({', '.join(run.path.name for run in runs)})"
    lines.append(f"mean ± 95 % confidence interval {window} (independent samples; 'drifting': the window's halves "
                 "differ; stationary from: detected start vs window start)")
    for quantity, unit in UNITS.items():
        rows = [r for r in summary.rows if r.quantity == quantity]
        reasons = [why for q, why in summary.not_available if q == quantity or (q == "element statistics"
                   and quantity in (RESIDENCE_HOLDUP, SOLID_FRACTION, AXIAL_VELOCITY, SPEED))]
        if quantity == MASS_FLOW and not rows and not reasons:
            continue
        lines.append(f"{quantity} ({unit})" + (f", {summary.complete_records} complete records"
                                                if quantity == RESIDENCE_RECORDS else ""))
        lines += [f"  (not available: {why})" for why in reasons]
        for r in rows:
            e = r.estimate
            lines.append(f"  {r.scope:<26} {e.text():<44} n_eff {e.independent_samples:6.1f}  "
                         f"stationary from {_start(e.detected_start)} (window from {_start(e.chosen_start)})")
    lines += systematics.lines_for(summary.parameters)
    return "\n".join(lines)


# ---- sweeps: several runs against a reference ----------------------------------------------------

@dataclass(frozen=True)
class ComparisonRow:
    variant: str
    quantity: str
    scope: str
    reference: Estimate
    value: Estimate
    difference: Difference


def combined_rows(runs: Sequence[Run], start: float | None = None, end: float | None = None) -> dict[Key, Estimate]:
    """Replicas (runs that differ only in the seed) combined quantity by quantity, each over its
    record from `start` s on up to `end` s (all of it when None)."""
    if not runs:
        raise ValueError("no run directories")
    combined = combine_summaries([summarise(run, start, end) for run in runs])
    return {(r.quantity, r.scope): r.estimate for r in combined.rows}


def compare_runs(reference: Sequence[Run], variants: Mapping[str, Sequence[Run]],
                 start: float | None = None, end: float | None = None) -> list[ComparisonRow]:
    """Each variant against the reference, quantity by quantity: difference ± 95 % interval; every
    run over its record from `start` s on up to `end` s (all of it when None)."""
    base = combined_rows(reference, start, end)
    rows = []
    for label, runs in variants.items():
        for key, value in combined_rows(runs, start, end).items():
            if key in base:
                rows.append(ComparisonRow(label, *key, base[key], value, difference(base[key], value)))
    return rows


def sweep_markdown(rows: Sequence[ComparisonRow]) -> str:
    lines = ["| variant | quantity | scope | reference | variant | difference | significant |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        unit = UNITS[r.quantity]
        lines.append(f"| {r.variant} | {r.quantity} ({unit}) | {r.scope} | {r.reference.text()} | {r.value.text()} | "
                     f"{r.difference.text(unit)} | {'yes' if r.difference.significant else 'no'} |")
    return "\n".join(lines) + "\n"


def write_sweep_csv(rows: Sequence[ComparisonRow], path: Path | str) -> None:
    def number(value: float | None) -> object:
        return "" if value is None or not math.isfinite(value) else value

    with open(path, "w", newline="", encoding="utf-8") as stream:
        writer = csv.writer(stream)
        writer.writerow(["variant", "quantity", "unit", "scope", "reference_mean", "reference_half_width",
                         "variant_mean", "variant_half_width", "difference", "difference_half_width", "significant",
                         "resolved"])
        for r in rows:
            writer.writerow([r.variant, r.quantity, UNITS[r.quantity], r.scope, number(r.reference.mean),
                             number(r.reference.half_width), number(r.value.mean), number(r.value.half_width),
                             number(r.difference.value), number(r.difference.half_width), r.difference.significant,
                             r.difference.inputs_resolved])
