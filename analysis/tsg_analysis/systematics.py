"""The systematic errors the accuracy studies measured, set beside a run's statistical error.

The registry (systematics.json beside this module) holds, per accuracy study, the error of each
ladder point against the study's reference, quantity by quantity, at its worst scope: the
difference ± 95 % and the bound |difference| + half-width, relative to the reference's mean
(tsg_analysis.accuracy). `tsg-analysis systematics add STUDY_DIR --name NAME --window TEXT` adds a
study from its accuracy.json (replacing one of the same name). The runner's summary and the report
list, for the settings a run used (time step, mesh tolerance, particle size) at the run's case and
scale, what the registry holds: the measured change to the nearest other setting the study ran, or
"not measured" where no study ran that setting.
"""
from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from .parameters import RunParameters
from .run_files import AnalysisInputError

if TYPE_CHECKING:
    from .paired import PairedRow

REGISTRY = Path(__file__).with_name("systematics.json")
SETTINGS = {"dt_fraction": "time step", "mesh_tolerance": "mesh tolerance", "d_mean": "mean diameter"}
UNITS = {"dt_fraction": " of the Rayleigh time", "mesh_tolerance": " m", "d_mean": " m"}


@dataclass(frozen=True)
class Measured:
    study: str  # the study's name in the registry
    where: str  # its folder (studies/accuracy/...)
    window: str  # how its runs were sampled (e.g. "0.5 s from the kept steady states at 1.5 s")
    case: str
    scale: str
    setting: str  # one of SETTINGS
    reference: str  # the study's reference value of the setting
    value: str  # the point's value
    quantity: str
    scope: str  # the worst scope of the quantity
    relative: float  # (point − reference) / reference mean, at that scope
    relative_half_width: float  # its 95 % half-width, relative
    relative_bound: float  # the largest relative bound over the quantity's scopes
    significant: bool

    def text(self) -> str:
        change = "not resolved" if not self.significant else "significant"
        return (f"{self.quantity} {self.relative:+.1%} ± {self.relative_half_width:.1%} ({self.scope}, {change}; "
                f"bound {self.relative_bound:.1%})")


def from_accuracy(study_dir: Path, name: str, window: str, where: str | None = None) -> list[Measured]:
    """The points of the study's accuracy.json whose setting is one of SETTINGS, quantity by quantity."""
    path = Path(study_dir) / "accuracy.json"
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise AnalysisInputError(f"{path}: not found (run tsg-accuracy {study_dir} first)") from None
    settings = data.get("reference", {}).get("settings")
    if not settings:
        raise AnalysisInputError(f"{path}: no reference settings (made by a tsg-accuracy before they were recorded: "
                                 "run the study again with --no-run to rewrite it)")
    found = []
    for point in data["points"]:
        if point["setting"] not in SETTINGS or point["state"] != "done":
            continue
        by_quantity: dict[str, list[dict]] = {}
        for error in point["errors"]:
            if error.get("difference") is not None and math.isfinite(error.get("relative_bound") or math.nan):
                by_quantity.setdefault(error["quantity"], []).append(error)
        for quantity, errors in by_quantity.items():
            worst = max(errors, key=lambda e: e["relative_bound"])
            mean = worst["reference"]["mean"]
            found.append(Measured(name, where or str(study_dir), window, data["case"], data["scale"], point["setting"],
                                  str(settings[point["setting"]]), point["value"], quantity, worst["scope"],
                                  worst["difference"]["value"] / mean, worst["difference"]["half_width"] / abs(mean),
                                  worst["relative_bound"], bool(worst["significant"])))
    if not found:
        raise AnalysisInputError(f"{path}: no finished point of {', '.join(SETTINGS)} with errors")
    return found


def from_paired(rows: Sequence[PairedRow], parameters: RunParameters, name: str, where: str, window: str,
                setting: str, value: str) -> list[Measured]:
    """A paired study's rows (tsg_analysis.paired.paired_study: a setting against the reference, state by
    state) at the worst scope of each quantity; the reference's value of the setting from its parameters."""
    if setting not in SETTINGS:
        raise AnalysisInputError(f"setting {setting!r} is not allowed: one of {', '.join(SETTINGS)}")
    reference = run_settings(parameters)[setting]
    if reference is None or parameters.case is None or parameters.scale is None:
        raise AnalysisInputError(f"the reference's parameters do not record its case, scale and {setting}")
    case, run_scale = parameters.case, parameters.scale
    found = []
    for quantity in dict.fromkeys(row.key[0] for row in rows):
        worst = max((row for row in rows if row.key[0] == quantity), key=lambda row: row.bound)
        scale = abs(worst.reference)
        difference = worst.difference
        found.append(Measured(name, where, window, case, run_scale, setting, f"{reference:g}", value,
                              quantity, worst.key[1], difference.mean / scale, difference.half_width / scale,
                              worst.bound, bool(abs(difference.mean) > difference.half_width)))
    if not found:
        raise AnalysisInputError(f"study {name}: no paired rows")
    return found


def load(registry: Path = REGISTRY) -> list[Measured]:
    if not registry.is_file():
        return []
    return [Measured(**entry) for entry in json.loads(registry.read_text(encoding="utf-8"))]


def add(entries: Sequence[Measured], registry: Path = REGISTRY) -> list[Measured]:
    """The registry with `entries`' studies replaced by them."""
    names = {e.study for e in entries}
    kept = [e for e in load(registry) if e.study not in names] + list(entries)
    registry.write_text(json.dumps([asdict(e) for e in kept], indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    return kept


def run_settings(parameters: RunParameters) -> dict[str, float | None]:
    """The run's value of each setting (params.json); None where the run does not record it."""
    def number(text: object) -> float | None:
        try:
            return float(text)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            return None
    return {"dt_fraction": number(parameters.variables.get("dt_fraction")), "d_mean": parameters.d_mean,
            "mesh_tolerance": parameters.mesh_tolerance}


def _same(a: str | float | None, b: str | float | None) -> bool:
    try:
        return a is not None and b is not None and math.isclose(float(a), float(b), rel_tol=1e-9)
    except ValueError:
        return False


def lines_for(parameters: RunParameters | None, entries: Sequence[Measured] | None = None) -> list[str]:
    """Per setting the run used: what the registry measured for it, or that nothing was."""
    if parameters is None:
        return ["systematic errors: the run's parameters are unknown (no params.json)"]
    entries = load() if entries is None else entries
    mine = [e for e in entries if e.case == parameters.case and e.scale == parameters.scale]
    lines = [f"systematic errors measured for this run's settings (studies in {REGISTRY.name}; the statistical "
             "error is above):"]
    for setting, value in run_settings(parameters).items():
        name = f"{SETTINGS[setting]} {'?' if value is None else f'{value:g}'}{UNITS[setting]}"
        as_reference = [e for e in mine if e.setting == setting and _same(e.reference, value)]
        as_point = [e for e in mine if e.setting == setting and _same(e.value, value)]
        if not as_reference and not as_point:
            lines.append(f"  {name}: not measured at {parameters.scale} scale for the {parameters.case} case")
            continue
        for e in as_reference:   # the change had the run used the study's other point
            lines.append(f"  {name}: {e.value} instead changes {e.text()} — study {e.study} ({e.where}; {e.window})")
        for e in as_point:       # the run used a point: its change from the study's reference
            lines.append(f"  {name}: against {e.reference} (the study's reference) it changes {e.text()} — study "
                         f"{e.study} ({e.where}; {e.window})")
    return lines
