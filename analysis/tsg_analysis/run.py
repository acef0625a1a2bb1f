"""`Run`: the one door to a run directory.

A `Run` reads each of the run's files once, on first use (zones.txt, elements.txt, massflow.txt,
residence.txt, the run parameters), owns its time axis (the step clock of massflow.txt) and the one
window rule, and gives the key estimates. The report, the summary, the accuracy and domain tools,
the validation helpers, the sweep and the scripts take a `Run`, never a path, so that one quantity
over one window is one number whichever tool prints it.

The window rule, for a window [start, end] in s (either bound None: open):
- an averaged sample (an element block) enters when its whole averaging interval lies inside: it
  begins at or after `start` and ends by `end`, judged in time steps (half a step of slack, so
  that a bound on a block's edge is never lost to rounding);
- a residence record enters when it is complete (outlet or periodic pass) and ends in (start, end];
- a mass-flow row enters when the middle of its interval lies in (start, end] (massflow.sensor_flows).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from .massflow import StepClock, sensor_flows, step_clock
from .model import (
    AXIAL_VELOCITY,
    DOMAIN_FLUX,
    KEY_UNITS,
    MASS_FLOW,
    RESIDENCE_HOLDUP,
    RESIDENCE_RECORDS,
    SOLID_FRACTION,
    SPEED,
    Key,
)
from .parameters import RunParameters, read_run_parameters
from .profiles import block_mask, domain_throughput, element_estimates, element_holdup_residence, holdup_residence
from .rtd import mean_residence
from .run_files import (
    ELEMENT_TYPES,
    RTD_EXIT_REASONS,
    AnalysisInputError,
    ElementStatistics,
    MassFlowRecord,
    ResidenceRecords,
    SqueezeRecords,
    Zones,
    earlier_segment_files,
    read_element_statistics,
    read_massflow,
    read_residence,
    read_squeezes,
    read_zones,
)
from .squeezes import SqueezeLedger, squeeze_ledger
from .uncertainty import Estimate

ELEMENT_QUANTITIES = ((SOLID_FRACTION, "solid_fraction"), (AXIAL_VELOCITY, "mean_axial_velocity"), (SPEED, "mean_speed"))


@dataclass(frozen=True)
class ElementAverages:
    """What the element blocks of one window give."""

    by_zone: dict[str, list[Estimate]]  # solid_fraction / mean_speed / mean_axial_velocity -> one per zone
    used: np.ndarray  # the blocks inside the window
    throughput: Estimate  # kg/h, the domain flux Σ m v_x / L
    holdup_residence: dict[str, Estimate]  # element type / "total" -> s, hold-up over throughput
    element_holdup_residence: list[Estimate]  # one per zone, s, its hold-up over the throughput


class Run:
    """One run directory, each file read once, lazily; AnalysisInputError (naming the file) for a
    file that is missing or unusable, raised where the part that needs it asks for it."""

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        if not self.path.is_dir():
            raise AnalysisInputError(f"{self.path}: not a directory")

    def __repr__(self) -> str:
        return f"Run({str(self.path)!r})"

    # ---- the files -----------------------------------------------------------------------------

    @cached_property
    def zones(self) -> Zones:
        return read_zones(self.path / "zones.txt")

    @cached_property
    def elements(self) -> ElementStatistics:
        """elements.txt, with the earlier segments' elements.upto-*.txt of a run made in segments."""
        return read_element_statistics(self.path)

    @cached_property
    def massflow(self) -> MassFlowRecord:
        record = read_massflow(self.path / "massflow.txt")
        if len(record.time) == 0:
            raise AnalysisInputError(f"{self.path / 'massflow.txt'}: only its header, no mass-flow rows: the run "
                                     "stopped (or is still) before its first mass-flow output")
        return record

    @cached_property
    def residence(self) -> ResidenceRecords:
        return read_residence(self.path / "residence.txt")

    @cached_property
    def squeezes(self) -> SqueezeRecords:
        return read_squeezes(self.path / "squeezes.txt")

    @cached_property
    def parameters(self) -> RunParameters:
        return read_run_parameters(self.path)

    @cached_property
    def log(self) -> str:
        """The text of log.lammps."""
        path = self.path / "log.lammps"
        if not path.is_file():
            raise AnalysisInputError(f"{path}: file not found (no log: the run has not been made)")
        return path.read_text(encoding="utf-8", errors="replace")

    @property
    def segment_logs(self) -> list[str]:
        """The logs of a run made in segments (cases/slurm/segment.sh): each earlier segment's
        log.upto-<step>.lammps in step order, then log.lammps."""
        earlier = earlier_segment_files(self.path, "log", ".lammps")
        return [p.read_text(encoding="utf-8", errors="replace") for p in earlier] + [self.log]

    # ---- the time axis -------------------------------------------------------------------------

    @cached_property
    def clock(self) -> StepClock:
        clock = step_clock(self.massflow)
        if clock is None:
            raise AnalysisInputError(f"{self.path / 'massflow.txt'}: fewer than 2 rows at different steps: "
                                     "no time axis (s per step)")
        return clock

    @cached_property
    def block_times(self) -> tuple[np.ndarray, np.ndarray]:
        """Begin and end times (s) of each element block; a block averages the interval before its step."""
        steps = self.elements.timesteps
        if len(steps) < 2:
            raise AnalysisInputError(f"{self.path / 'elements.txt'}: fewer than 2 blocks: too short a record to cut")
        ends = self.clock.time(steps)
        return ends - float(np.median(np.diff(ends))), ends

    def _block_axis(self, start: float | None, end: float | None) -> np.ndarray:
        """Block end times in s; in steps for a whole-record average of a run without a time axis."""
        if start is None and end is None:
            try:
                return self.clock.time(self.elements.timesteps)
            except AnalysisInputError:
                return self.elements.timesteps.astype(np.float64)
        return self.clock.time(self.elements.timesteps)

    # ---- the window rule -----------------------------------------------------------------------

    def blocks(self, start: float | None = None, end: float | None = None) -> np.ndarray:
        """The element blocks whose whole averaging interval lies in [start, end]."""
        first = None if start is None else self.clock.step(start)
        last = None if end is None else self.clock.step(end)
        return block_mask(self.elements, first, last)

    def records(self, start: float | None = None, end: float | None = None) -> np.ndarray:
        """The complete residence records (outlet or periodic pass) that end in (start, end]."""
        records = self.residence
        chosen = np.isin(records.exit_reason, RTD_EXIT_REASONS)
        if start is not None:
            chosen &= records.exit_time > start
        if end is not None:
            chosen &= records.exit_time <= end
        return chosen

    # ---- the estimates -------------------------------------------------------------------------

    def sensor_flows(self, start: float | None = None, end: float | None = None) -> dict[str, Estimate]:
        """Mean flow (kg/h) of each sensor ± 95 %."""
        return sensor_flows(self.massflow, start, end)

    def element_averages(self, start: float | None = None, end: float | None = None) -> ElementAverages:
        times = self._block_axis(start, end)
        by_zone, used = element_estimates(self.elements, self.zones, self.blocks(start, end), times)
        return ElementAverages(by_zone, used, domain_throughput(self.elements, self.zones, used, times),
                               holdup_residence(self.elements, self.zones, used, times),
                               element_holdup_residence(self.elements, self.zones, used, times))

    def record_types(self) -> list[str]:
        """The element types of the residence scopes: those of zones.txt, or those the records visited."""
        try:
            return self.zones.types_present
        except AnalysisInputError:
            return [t for t in ELEMENT_TYPES if np.any(self.residence.time_by_type[t] > 0)]

    def residence_means(self, start: float | None = None, end: float | None = None) -> dict[str, Estimate]:
        """Mean residence time (s) ± 95 % of the complete records of the window: "total" and per
        element type."""
        chosen = self.records(start, end)
        if not chosen.any():
            raise AnalysisInputError(f"0 complete records ({', '.join(RTD_EXIT_REASONS)}) in the window: it is "
                                     "shorter than one pass")
        records = self.residence
        exits = records.exit_time[chosen]
        means = {kind: mean_residence(records.time_by_type[kind][chosen], exits) for kind in self.record_types()}
        means["total"] = mean_residence(records.residence_time[chosen], exits)
        return means

    def element_keys(self, start: float | None = None, end: float | None = None,
                     labels: list[str | None] | None = None) -> dict[Key, Estimate]:
        """The element statistics' estimates by (quantity, scope): domain flux, hold-up residence
        times per element type and per element, per-element solid fraction, axial velocity and speed (`labels`: each zone's scope,
        None to leave it out; default the zones' own labels)."""
        averages = self.element_averages(start, end)
        names = list(self.zones.labels) if labels is None else labels
        found: dict[Key, Estimate] = {(MASS_FLOW, DOMAIN_FLUX): averages.throughput}
        found.update({(RESIDENCE_HOLDUP, kind): e for kind, e in averages.holdup_residence.items()})
        # per element too: the residence-time panel of the paper's Fig. 9
        found.update({(RESIDENCE_HOLDUP, label): e for label, e in zip(names, averages.element_holdup_residence)
                      if label is not None})
        for quantity, name in ELEMENT_QUANTITIES:
            found.update({(quantity, label): e for label, e in zip(names, averages.by_zone[name]) if label is not None})
        return found

    def squeeze_ledger(self, start: float | None = None, end: float | None = None) -> SqueezeLedger:
        """The squeeze events that end in (start, end] (the records' rule), with the zones for where."""
        return squeeze_ledger(self.squeezes, self.zones, start, end)

    def key_estimates(self, start: float | None = None, end: float | None = None,
                      reference_zones: Zones | None = None) -> dict[Key, Estimate]:
        """The key quantities of the accuracy study over [start, end]: mass flow by the domain flux,
        per-element solid fraction, axial velocity and speed (labelled in `reference_zones`'
        numbering when given, Zones.aligned_labels), and the mean residence time where at least
        2 complete records end in the window."""
        if self.blocks(start, end).sum() < 2:
            raise AnalysisInputError(f"{self.path / 'elements.txt'}: fewer than 2 blocks between {start} s and {end} s")
        labels = self.zones.aligned_labels(reference_zones) if reference_zones is not None else None
        found = {key: e for key, e in self.element_keys(start, end, labels).items() if key[0] in KEY_UNITS}
        if (self.path / "residence.txt").is_file() and self.records(start, end).sum() >= 2:
            found[(RESIDENCE_RECORDS, "total")] = self.residence_means(start, end)["total"]
        return found
