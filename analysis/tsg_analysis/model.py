"""The analysis data model: settings, what was worked out for one run, and a report of several runs.
report.py fills these; report_files.py and the notebooks read them."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .cross_section import DEFAULT_BIN_SIZE, SolidFractionMap
from .massflow import STEADY_TOLERANCE, PlaneFlows, SteadyState, StepClock
from .parameters import RunParameters
from .profiles import ElementProfile
from .rtd import RTDComparison, RTDStatistics
from .run_files import MassFlowRecord, ResidenceRecords, Zones
from .squeezes import SqueezeLedger
from .uncertainty import Difference, Estimate

if TYPE_CHECKING:
    from .run import Run

# The quantities every run reports (summary, report, sweep tables), with their units
MASS_FLOW, RESIDENCE_RECORDS, RESIDENCE_HOLDUP = "mass flow", "residence time (records)", "residence time (hold-up/throughput)"
SOLID_FRACTION, AXIAL_VELOCITY, SPEED = "solid fraction", "axial velocity", "speed"
# per element, the paper's Fig. 9 quantities: solid fraction, speed (mean |v|) and axial velocity
UNITS = {MASS_FLOW: "kg/h", RESIDENCE_RECORDS: "s", RESIDENCE_HOLDUP: "s", SOLID_FRACTION: "-", AXIAL_VELOCITY: "m/s",
         SPEED: "m/s"}
DOMAIN_FLUX = "domain flux Σ m v_x / L"
# the key quantities of the accuracy study (accuracy.py) and the domain comparison
KEY_UNITS = {MASS_FLOW: UNITS[MASS_FLOW], SOLID_FRACTION: UNITS[SOLID_FRACTION], AXIAL_VELOCITY: UNITS[AXIAL_VELOCITY],
             SPEED: "m/s", RESIDENCE_RECORDS: UNITS[RESIDENCE_RECORDS]}
Key = tuple[str, str]  # (quantity, scope)


@dataclass(frozen=True)
class Settings:
    steady_window: float | None = None  # s per steady-state window; None: one screw revolution of the run
    steady_tolerance: float = STEADY_TOLERANCE
    require_steady: bool = False  # True: no time averages unless steady; False: whole record, marked transient
    bin_size: float = DEFAULT_BIN_SIZE  # m, cross-section maps
    particle_density: float | None = None  # kg/m^3 for dumps without a mass column; None: the run's rho_p
    snapshot: bool = True


@dataclass
class RunAnalysis:
    """What could be worked out for one run directory."""

    label: str
    run_dir: Path
    out_dir: Path
    source: Run | None = None  # the run directory's files; None when it is not a directory
    parameters: RunParameters | None = None
    zones: Zones | None = None
    records: ResidenceRecords | None = None
    massflow: MassFlowRecord | None = None
    steady: SteadyState | None = None
    clock: StepClock | None = None
    window: tuple[float, float] | None = None  # s; the whole record when transient
    transient: bool = False
    rtd_samples: dict[str, np.ndarray] = field(default_factory=dict)
    rtd_stats: dict[str, RTDStatistics] = field(default_factory=dict)
    rtd_means: dict[str, Estimate] = field(default_factory=dict)  # scope -> mean residence time ± interval
    profile: ElementProfile | None = None
    holdup_residence: dict[str, Estimate] = field(default_factory=dict)  # type/total -> s, hold-up/throughput
    throughput: Estimate | None = None  # kg/h, the flux averaged over the domain (elements.txt)
    sensor_flows: dict[str, Estimate] = field(default_factory=dict)  # sensor -> kg/h
    maps: dict[str, SolidFractionMap] = field(default_factory=dict)
    plane_flows: PlaneFlows | None = None
    log_summary: dict | None = None
    squeezes: SqueezeLedger | None = None  # squeezes.txt (fix squeeze/ledger); None without it
    figures: dict[str, str] = field(default_factory=dict)  # part -> file name
    notes: list[str] = field(default_factory=list)  # input issues that did not stop a part
    missing: list[tuple[str, str]] = field(default_factory=list)  # (part, reason)

    def estimates(self) -> dict[tuple[str, str], Estimate]:
        """Every reported mean by (quantity, scope), the keys of the summary and the sweep tables."""
        found: dict[tuple[str, str], Estimate] = {(MASS_FLOW, name): e for name, e in self.sensor_flows.items()}
        if self.throughput is not None:
            found[(MASS_FLOW, DOMAIN_FLUX)] = self.throughput
        found.update({(RESIDENCE_RECORDS, scope): e for scope, e in self.rtd_means.items()})
        found.update({(RESIDENCE_HOLDUP, scope): e for scope, e in self.holdup_residence.items()})
        if self.profile is not None:
            for quantity, name in ((SOLID_FRACTION, "solid_fraction"), (AXIAL_VELOCITY, "mean_axial_velocity"),
                                   (SPEED, "mean_speed")):
                found.update({(quantity, label): e for label, e in
                              zip(self.profile.zones.labels, self.profile.estimates.get(name, []))})
        return found


@dataclass
class Report:
    runs: list[RunAnalysis]
    comparisons: list[tuple[str, str, RTDComparison]]  # (reference, run, comparison)
    figures: dict[str, str]
    missing: list[tuple[str, str]]  # report-wide (part, reason)
    settings: Settings
    differences: list[tuple[str, str, str, str, Difference]] = field(default_factory=list)
    # (reference, run, quantity, scope, run − reference)

    @property
    def not_produced(self) -> list[tuple[str, str, str]]:
        entries = [(run.label, part, reason) for run in self.runs for part, reason in run.missing]
        return entries + [("all runs", part, reason) for part, reason in self.missing]
