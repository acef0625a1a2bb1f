"""Accuracy against cost (issue 15): the error of each key quantity of a run against a reference run,
with its 95 % interval, the cost of the run, and the cheapest setting that meets a tolerance.

Pure logic on run directories (cases/accuracy.py runs the ladders and writes the outputs):

- The key quantities of a run are `Run.key_estimates` (mass flow by the flux estimator Σ m v_x / L,
  per-element solid fraction, axial velocity and speed, mean residence time where complete records
  exist), over the sampling record up to `end` s (the sampling ladder truncates the reference's own
  record at `sampling_ends`).
- `point_errors(reference, value)`: each point's error Δ = value − reference ± interval; its bound
  |Δ| + half-width is the largest error the 95 % interval allows. A fidelity point's interval is
  that of the difference of two runs (uncertainty.difference); a sampling point's (the reference's
  own record truncated, so not independent of it) is the half-width of its own estimate: a shorter
  or earlier window has a bias Δ as well as a statistical error, and both count.
- Several scopes looked at together (the 8 elements of a quantity, or every quantity of a control
  run) would show a "significant" 95 % difference by chance in 5 % of the scopes each. A quantity's
  (or a control's) difference counts as resolved only when it is significant with simultaneous
  intervals: Bonferroni, each half-width widened by `family_factor(m)` = z(1 − 0.025/m) / z(0.975)
  (normal quantiles; the t quantiles of few independent samples would widen slightly more).
- `verdict(error, tolerance, factor)`: meets (bound within the tolerance), fails (even the interval's
  lower end |Δ| − half-width exceeds it), undecided (the interval straddles the tolerance) or too short.
- `cheapest(points, quantity, tolerance)`: the cheapest point whose every scope meets the tolerance
  (simultaneous intervals over the quantity's scopes).
- `run_cost(run)`: loop wall time, ranks, steps, atoms and simulated time from log.lammps.
- Replicas (runs of one setting that differ only in the fill seed): `replica_key_estimates` combines
  their key quantities (uncertainty.combine_replicas: replica window means where each window is too
  short for a time-series interval), `RunCost.of_replicas` adds up their cost.
"""
from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .liggghts_log import parse_thermo
from .model import KEY_UNITS, Key
from .run import Run
from .run_files import AnalysisInputError, Zones
from .uncertainty import Difference, Estimate, combine_replicas, difference

MEETS, FAILS, UNDECIDED, TOO_SHORT = "meets", "fails", "undecided", "window too short"


# ---- key quantities of replicas ------------------------------------------------------------------

def replica_key_estimates(runs: Sequence[Run], ends: Sequence[float | None] | None = None,
                          reference_zones: Zones | None = None) -> dict[Key, Estimate]:
    """Key quantities (Run.key_estimates) of replicas of one setting combined key by key (keys every
    replica has); `ends`: each replica's own end of record (the sampling ladder), or None."""
    if not runs:
        raise AnalysisInputError("no finished replica")
    ends = list(ends) if ends is not None else [None] * len(runs)
    each = [run.key_estimates(end=end, reference_zones=reference_zones) for run, end in zip(runs, ends)]
    return {key: combine_replicas([e[key] for e in each]) for key in each[0] if all(key in e for e in each)}


def sampling_ends(run: Run, fractions: Sequence[float]) -> list[float]:
    """End times (s) of the first `fractions` of a run's sampling record (its element blocks)."""
    begins, ends = run.block_times
    return [float(begins[0]) + f * (float(ends[-1]) - float(begins[0])) for f in fractions]


# ---- the error of a point and its verdict --------------------------------------------------------

@dataclass(frozen=True)
class Tolerance:
    """A user tolerance: relative ('5%': of the reference value of each scope) or absolute (in the
    quantity's unit)."""

    value: float
    relative: bool

    @classmethod
    def parse(cls, text: str) -> Tolerance:
        relative = text.strip().endswith("%")
        number = text.strip().rstrip("%")
        try:
            value = float(number)
        except ValueError:
            raise ValueError(f"--tolerance {text} is not allowed: a positive number, with % for relative") from None
        if not value > 0 or not math.isfinite(value):
            raise ValueError(f"--tolerance {text} is not allowed: a positive number, with % for relative")
        return cls(value / 100 if relative else value, relative)

    def allowed(self, reference_mean: float) -> float:
        return self.value * abs(reference_mean) if self.relative else self.value

    def text(self) -> str:
        return f"{self.value:.3g} (relative, {self.value:.3%})" if self.relative else f"{self.value:g} (absolute)"


@dataclass(frozen=True)
class PointError:
    """The error of one quantity in one scope at one ladder point against the reference.

    Fidelity point: `difference` = value − reference ± 95 % interval of the difference. Sampling point
    (the reference's own record truncated): `difference` None; the error is value − reference (the
    window's bias) ± the half-width of `value` (its statistical error)."""

    quantity: str
    scope: str
    reference: Estimate
    value: Estimate
    difference: Difference | None

    @property
    def resolved_inputs(self) -> bool:
        if self.difference is None:
            return self.value.resolved
        return self.difference.inputs_resolved

    @property
    def significant(self) -> bool:
        return self.difference is not None and self.difference.significant

    @property
    def offset(self) -> float:
        """value − reference: a fidelity point's difference, a sampling point's window bias."""
        return self.value.mean - self.reference.mean if self.difference is None else self.difference.value

    @property
    def half_width(self) -> float:
        return self.value.half_width if self.difference is None else self.difference.half_width

    @property
    def bound(self) -> float:
        """The largest |error| the 95 % interval allows, |offset| + half-width, for every ladder; nan
        when the inputs are not resolved."""
        if not self.resolved_inputs:
            return math.nan
        return abs(self.offset) + self.half_width

    @property
    def lower(self) -> float:
        """The smallest |error| the 95 % interval allows (0 when it covers zero)."""
        if not self.resolved_inputs:
            return math.nan
        return max(0.0, abs(self.offset) - self.half_width)

    @property
    def relative_bound(self) -> float:
        """bound / |reference|; nan when the reference's own interval covers zero (no scale to relate to)."""
        if not (self.reference.resolved and abs(self.reference.mean) > self.reference.half_width):
            return math.nan
        return self.bound / abs(self.reference.mean)

    def text(self) -> str:
        unit = KEY_UNITS.get(self.quantity, "")
        unit = "" if unit == "-" else unit
        if self.difference is not None:
            return self.difference.text(unit)
        if not self.value.resolved:
            return self.value.text(unit)
        unit = f" {unit}" if unit else ""
        relative = f" ({self.offset / self.reference.mean:+.1%})" if self.reference.mean != 0 else ""
        return f"window bias {self.offset:+.2g}{unit}{relative}, statistical ± {self.half_width:.2g}{unit}"

    def as_dict(self) -> dict:
        def clean(v: float) -> float | None:
            return v if math.isfinite(v) else None

        return {"quantity": self.quantity, "scope": self.scope, "reference": self.reference.as_dict(),
                "value": self.value.as_dict(),
                "difference": self.difference.as_dict() if self.difference is not None else None,
                "significant": self.significant, "resolved_inputs": self.resolved_inputs,
                "bound": clean(self.bound), "relative_bound": clean(self.relative_bound), "text": self.text()}


def point_errors(reference: Mapping[Key, Estimate], value: Mapping[Key, Estimate], sampling: bool = False) -> list[PointError]:
    """Errors of every key both runs have, in the reference's order."""
    return [PointError(key[0], key[1], reference[key], value[key],
                       None if sampling else difference(reference[key], value[key]))
            for key in reference if key in value]


def family_factor(scopes: int) -> float:
    """Bonferroni: the half-width of `scopes` simultaneous 95 % intervals over that of one."""
    from scipy.stats import norm

    return float(norm.ppf(1 - 0.025 / max(scopes, 1)) / norm.ppf(0.975))


def resolved_scopes(errors: Sequence[PointError], quantity: str | None = None) -> list[PointError]:
    """The errors (of `quantity`, or all) that stay significant with simultaneous intervals over them."""
    family = [e for e in errors if (quantity is None or e.quantity == quantity) and e.difference is not None
              and e.resolved_inputs]
    factor = family_factor(len(family))
    return [e for e in family if e.difference is not None
            and abs(e.difference.value) > factor * e.difference.half_width]


def verdict(error: PointError, tolerance: Tolerance, factor: float = 1.0) -> str:
    """`factor` widens the half-width (simultaneous intervals over several scopes)."""
    if not error.resolved_inputs:
        return TOO_SHORT
    if tolerance.relative and not math.isfinite(error.relative_bound):
        return UNDECIDED  # the reference's interval covers zero: no relative scale
    allowed = tolerance.allowed(error.reference.mean)
    widen = (factor - 1.0) * error.half_width
    if error.bound + widen <= allowed:
        return MEETS
    if error.lower - widen > allowed:
        return FAILS
    return UNDECIDED


def quantity_verdict(errors: Sequence[PointError], quantity: str, tolerance: Tolerance) -> str:
    """One verdict over every scope of a quantity (simultaneous intervals): meets only when every
    scope meets; fails when any fails; otherwise too short / undecided."""
    mine = [e for e in errors if e.quantity == quantity]
    factor = family_factor(len(mine))
    verdicts = [verdict(e, tolerance, factor) for e in mine]
    if not verdicts:
        return "not measured"
    if FAILS in verdicts:
        return FAILS
    if all(v == MEETS for v in verdicts):
        return MEETS
    return TOO_SHORT if TOO_SHORT in verdicts else UNDECIDED


def worst_relative(errors: Sequence[PointError], quantity: str) -> tuple[float, bool]:
    """The largest relative error bound over a quantity's scopes (per-scope 95 % intervals), and
    whether the quantity's error is resolved (simultaneous intervals): the y value of the
    error-against-cost figure. nan when no scope has a relative scale."""
    values = [e.relative_bound for e in errors if e.quantity == quantity and math.isfinite(e.relative_bound)]
    return (max(values) if values else math.nan), bool(resolved_scopes(errors, quantity))


@dataclass(frozen=True)
class Choice:
    label: str | None  # the chosen point, None when none meets
    cost: float | None
    message: str


def cheapest(points: Mapping[str, tuple[float, Sequence[PointError]]], quantity: str, tolerance: Tolerance) -> Choice:
    """points: label -> (cost, errors). The cheapest point whose `quantity` meets `tolerance` in
    every scope; otherwise why none does."""
    verdicts = {label: quantity_verdict(errors, quantity, tolerance) for label, (_, errors) in points.items()}
    meeting = [(points[label][0], label) for label, v in verdicts.items() if v == MEETS and math.isfinite(points[label][0])]
    if meeting:
        cost, label = min(meeting)
        return Choice(label, cost, f"{label} ({cost:.4g} core-s)")
    counts = {v: sum(1 for x in verdicts.values() if x == v) for v in (FAILS, UNDECIDED, TOO_SHORT)}
    detail = ", ".join(f"{n} {v}" for v, n in counts.items() if n)
    return Choice(None, None, f"none resolved to this tolerance ({detail or 'no points'})")


RECOMMENDATION_TOLERANCES = (0.02, 0.05, 0.10)  # relative: the table "for a tolerance of 2 / 5 / 10 %"


def recommend(points: Mapping[str, tuple[float, Sequence[PointError]]], reference_cost: float, quantity: str,
              tolerance: Tolerance) -> Choice:
    """The cheapest setting shown to be within `tolerance` of the best measured one: among the
    points cheaper than the reference, the cheapest that meets it; else the reference itself when
    every point dearer than it (a finer setting) meets it; else none, with why. points: label ->
    (cost rate, errors), costs in one unit with `reference_cost`."""
    cheaper = {label: v for label, v in points.items() if math.isfinite(v[0]) and v[0] < reference_cost}
    dearer = {label: v for label, v in points.items() if math.isfinite(v[0]) and v[0] >= reference_cost}
    verdicts = {label: quantity_verdict(errors, quantity, tolerance) for label, (_, errors) in points.items()}
    confirmed = bool(dearer) and all(verdicts[label] == MEETS for label in dearer)
    meeting = sorted((cost, label) for label, (cost, _) in cheaper.items() if verdicts[label] == MEETS)
    if meeting and confirmed:
        cost, label = meeting[0]
        return Choice(label, cost, f"{label} ({cost:.4g} core-s per simulated s)")
    if confirmed:
        return Choice("reference", reference_cost, f"the reference ({reference_cost:.4g} core-s per simulated s; "
                      f"every finer point within it: {', '.join(dearer)})")
    if not dearer:
        return Choice(None, None, "none: no finer point to confirm the reference against")
    why = ", ".join(f"{label} {verdicts[label]}" for label in dearer if verdicts[label] != MEETS)
    return Choice(None, None, f"none shown: the finer points do not confirm the reference ({why})")


# ---- cost ------------------------------------------------------------------------------------------

LOOP = re.compile(r"^Loop time of ([\d.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms", re.MULTILINE)


@dataclass(frozen=True)
class RunCost:
    """Per chunk of one run or of several (LIGGGHTS prints a 'Loop time' line for every `run` command
    and every chunk of `run N every M`): loop wall time, steps, particles and the simulated time it
    covered. Replicas (of_replicas) are their chunks together: they differ in their time step (the
    smallest particle of each fill), so in their steps and chunks, not in their simulated time."""

    loop_seconds: np.ndarray
    steps: np.ndarray
    start_time: np.ndarray  # s, simulated
    end_time: np.ndarray  # s, simulated
    ranks: int
    atoms: np.ndarray  # particles in each chunk
    runs: int = 1

    @classmethod
    def of_replicas(cls, costs: Sequence[RunCost]) -> RunCost:
        """The cost of replicas of one setting: all their chunks."""
        if len({c.ranks for c in costs}) != 1:
            raise AnalysisInputError("replicas of one setting ran on different numbers of ranks")
        def joined(name: str) -> np.ndarray:
            return np.concatenate([getattr(c, name) for c in costs])

        return cls(joined("loop_seconds"), joined("steps"), joined("start_time"), joined("end_time"), costs[0].ranks,
                   joined("atoms"), sum(c.runs for c in costs))

    @property
    def wall_seconds(self) -> float:
        return float(self.loop_seconds.sum())

    @property
    def core_seconds(self) -> float:
        return self.ranks * self.wall_seconds

    @property
    def simulated_seconds(self) -> float:
        """Of one run (the mean over replicas): the chunks of a run follow each other."""
        return float((self.end_time - self.start_time).sum()) / self.runs

    @property
    def core_seconds_per_simulated_second(self) -> float:
        """Per run (a rate of the setting, whatever the number of replicas)."""
        return self.core_seconds / (self.runs * self.simulated_seconds) if self.simulated_seconds > 0 else math.nan

    @property
    def steps_per_simulated_second(self) -> float:
        """1/dt: exact, whatever the machine's load (the wall-clock measures are not)."""
        return float(self.steps.sum()) / (self.runs * self.simulated_seconds) if self.simulated_seconds > 0 else math.nan

    @property
    def particle_steps_per_second(self) -> float:
        return float(self.atoms @ self.steps) / self.wall_seconds if self.wall_seconds > 0 else math.nan

    @property
    def mean_atoms(self) -> int:
        return round(float(self.atoms.mean()))

    def until(self, end: float) -> RunCost:
        """The cost up to simulated time `end` in each run (a chunk cut by `end` counts in proportion)."""
        span = np.maximum(self.end_time - self.start_time, 1e-300)
        cut = np.clip(end, self.start_time, self.end_time)
        share = (cut - self.start_time) / span
        return RunCost(self.loop_seconds * share, np.round(self.steps * share), self.start_time, cut, self.ranks,
                       self.atoms, self.runs)

    def as_dict(self) -> dict:
        return {"wall_seconds": self.wall_seconds, "runs": self.runs, "ranks": self.ranks, "steps": int(self.steps.sum()),
                "atoms": self.mean_atoms, "simulated_seconds": self.simulated_seconds, "core_seconds": self.core_seconds,
                "core_seconds_per_simulated_second": self.core_seconds_per_simulated_second,
                "steps_per_simulated_second": self.steps_per_simulated_second,
                "particle_steps_per_second": self.particle_steps_per_second}


def run_cost(run: Run) -> RunCost:
    """The cost of a finished run from its log.lammps: every chunk's loop time and simulated span."""
    log_path = run.path / "log.lammps"
    log = run.log
    loops = LOOP.findall(log)
    blocks = [b for b in parse_thermo(log) if "Time" in b and len(b["Time"])]
    if not loops or len(blocks) != len(loops):
        raise AnalysisInputError(f"{log_path}: {len(loops)} 'Loop time' lines and {len(blocks)} thermo blocks with "
                                 "a Time column: the run did not finish, or its thermo has no time")
    return RunCost(np.array([float(w) for w, *_ in loops]), np.array([int(s) for _, _, s, _ in loops]),
                   np.array([float(b["Time"][0]) for b in blocks]), np.array([float(b["Time"][-1]) for b in blocks]),
                   int(loops[-1][1]), np.array([int(a) for *_, a in loops]))
