"""Mass flow: steady-state decision from the sensors, mean sensor flows, and net flow through
planes counted from particle dumps.

Steady state (seed paper Sec. 4: "when the averaged mass flow rate is approximately equal for both
the inlet and outlet sensor"): the record is cut into windows of `window` seconds aligned to its
end; a window agrees when the inlet sensor (sensor_1) has a positive mean flow and the outlet
sensor (the last one) is within `tolerance` of it. The run is steady from the start of the first
window of the trailing run of agreeing windows, provided that run has at least `min_windows`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .dumps import ParticleFrame
from .run_files import AnalysisInputError, MassFlowRecord
from .uncertainty import Estimate, estimate_mean

STEADY_TOLERANCE = 0.05  # relative inlet/outlet difference
STEADY_MIN_WINDOWS = 2
SECONDS_PER_HOUR = 3600.0


@dataclass(frozen=True)
class SteadyState:
    reached: bool
    start_time: float | None  # s; None when not reached
    end_time: float  # s, end of the record
    window: float
    tolerance: float
    window_starts: np.ndarray  # (windows,)
    window_means: np.ndarray  # (windows, sensors) kg/h
    agree: np.ndarray  # (windows,)
    message: str


@dataclass(frozen=True)
class StepClock:
    """Simulation time of a time step, from the (step, time) pairs of massflow.txt."""

    dt: float
    step0: int
    time0: float

    def time(self, step: np.ndarray | int) -> np.ndarray:
        return self.time0 + (np.asarray(step, dtype=np.float64) - self.step0) * self.dt

    def step(self, time: float) -> float:
        return self.step0 + (time - self.time0) / self.dt


@dataclass(frozen=True)
class PlaneFlows:
    x: np.ndarray  # plane positions, m
    flow: np.ndarray  # net mass flow towards +x, kg/h
    duration: float  # s between the first and last frame used
    frames: int


def step_clock(record: MassFlowRecord) -> StepClock | None:
    if len(record.step) < 2 or record.step[-1] == record.step[0]:
        return None
    dt = (record.time[-1] - record.time[0]) / (record.step[-1] - record.step[0])
    return StepClock(float(dt), int(record.step[0]), float(record.time[0]))


def _row_durations(time: np.ndarray) -> np.ndarray:
    """Each row is the mean over the interval since the previous row; the first row is taken to
    cover as long as the second."""
    return np.diff(time, prepend=time[0] - (time[1] - time[0]) if len(time) > 1 else time[0])


def row_middles(time: np.ndarray) -> np.ndarray:
    """The middle of each row's interval, s: what the window rule places in a window."""
    return time - 0.5 * _row_durations(time)


def _span(record: MassFlowRecord) -> float:
    """Seconds the record covers (its first row covers an interval before its time)."""
    if len(record.time) == 0:
        return 0.0
    return float(record.time[-1] - record.time[0] + _row_durations(record.time)[0])


def window_means(record: MassFlowRecord, window: float) -> tuple[np.ndarray, np.ndarray]:
    """Start times and time-weighted mean flows of consecutive windows ending at the record's end."""
    if len(record.time) < 2:
        return np.empty(0), np.empty((0, record.flow.shape[1]))
    durations = _row_durations(record.time)
    start, end = record.time[0] - durations[0], record.time[-1]
    n_windows = int(np.floor((end - start) / window + 1e-9))
    starts = end - window * np.arange(n_windows, 0, -1)
    # a row belongs to the window holding the middle of its interval: immune to rounding of the edges
    which = np.searchsorted(starts, record.time - 0.5 * durations, side="right") - 1
    inside = which >= 0
    weights = np.bincount(which[inside], weights=durations[inside], minlength=n_windows)
    means = np.column_stack([
        np.bincount(which[inside], weights=(record.flow[:, k] * durations)[inside], minlength=n_windows)
        for k in range(record.flow.shape[1])])
    with np.errstate(invalid="ignore", divide="ignore"):
        return starts, means / weights[:, None]


def decide_steady_state(record: MassFlowRecord, window: float,
                        tolerance: float = STEADY_TOLERANCE, min_windows: int = STEADY_MIN_WINDOWS) -> SteadyState:
    starts, means = window_means(record, window)
    end = float(record.time[-1]) if len(record.time) else 0.0

    def verdict(reached: bool, start: float | None, agree: np.ndarray, message: str) -> SteadyState:
        return SteadyState(reached, start, end, window, tolerance, starts, means, agree, message)

    if record.flow.shape[1] < 2:
        return verdict(False, None, np.zeros(len(starts), bool),
                       "massflow.txt has a single sensor: steady state needs an inlet and an outlet sensor")
    if len(starts) < min_windows:
        return verdict(False, None, np.zeros(len(starts), bool),
                       f"the mass-flow record ({_span(record):.3g} s, to t = {end:.3g} s) is shorter than "
                       f"{min_windows} windows of {window:.4g} s")
    inlet, outlet = means[:, 0], means[:, -1]
    with np.errstate(invalid="ignore"):
        agree = (inlet > 0) & (np.abs(outlet - inlet) <= tolerance * inlet)
    trailing = len(agree) - (np.flatnonzero(~agree)[-1] + 1 if not agree.all() else 0)
    last = f"last {window:g} s window: inlet {inlet[-1]:.4g} kg/h, outlet ({record.sensor_names[-1]}) {outlet[-1]:.4g} kg/h"
    if trailing >= min_windows:
        start = float(starts[len(agree) - trailing])
        return verdict(True, start, agree,
                       f"steady from t = {start:.4g} s: inlet and outlet mean mass flows agree within "
                       f"{tolerance:.0%} in every {window:g} s window to the end ({last})")
    if inlet[-1] <= 0:
        reason = "no forward flow at the inlet sensor"
    else:
        reason = f"outlet differs from inlet by {abs(outlet[-1] - inlet[-1]) / inlet[-1]:.1%}"
    return verdict(False, None, agree,
                   f"never reached steady state: {reason} ({last}; needs {min_windows} consecutive windows "
                   f"within {tolerance:.0%} up to the end)")


def sensor_flows(record: MassFlowRecord, start: float | None, end: float | None = None) -> dict[str, Estimate]:
    """Mean flow (kg/h) of each sensor ± 95 % interval over the rows whose interval middle lies in
    (start, end] (all rows when start is None); rows are equal windows of the fix, so each counts once.
    Start-up detection runs on the whole record and is reported beside `start`."""
    middle = row_middles(record.time)
    low = -np.inf if start is None else start
    high = np.inf if end is None else end
    rows = (middle > low) & (middle <= high)
    if not rows.any():
        raise AnalysisInputError(f"massflow.txt has no rows between {low:.4g} s and {high:.4g} s")
    chosen = float(middle[rows][0])
    return {name: estimate_mean(record.flow[:, k][middle <= high], middle[middle <= high], chosen)
            for k, name in enumerate(record.sensor_names)}


def particle_masses(frame: ParticleFrame, density: float | None) -> np.ndarray:
    if "mass" in frame.columns:
        return frame.columns["mass"]
    if density is None:
        raise AnalysisInputError("dumps carry no 'mass' column and no particle density was given")
    return density * frame.volume


class PlaneFlowCounter:
    """Net mass flow through planes x = const, counted from consecutive frames: a particle present
    in both frames contributes its mass once per plane it has crossed (signed). This is exact for
    the net flux however often a particle oscillates between frames, as long as it moves less than
    half a period between frames (periodic domains) and is not inserted or deleted next to a plane
    between two frames. `period`: the x length of a periodic box, so that a wrap counts as a pass."""

    def __init__(self, x_planes: np.ndarray, period: float | None = None, density: float | None = None) -> None:
        self.x_planes = np.asarray(x_planes, dtype=np.float64)
        self.period, self.density = period, density
        self.crossed_mass = np.zeros(len(self.x_planes))
        self.previous: ParticleFrame | None = None
        self.first_time = self.last_time = 0.0
        self.frames = 0

    def add(self, frame: ParticleFrame, time: float) -> None:
        frame.require("id", "x")
        if self.previous is None:
            self.first_time = time
        else:
            _, before, after = np.intersect1d(self.previous.columns["id"], frame.columns["id"],
                                              assume_unique=True, return_indices=True)
            x0 = self.previous.columns["x"][before]
            x1 = frame.columns["x"][after]
            mass = particle_masses(frame, self.density)[after]
            if self.period is not None:
                step = x1 - x0
                x1 = x0 + step - self.period * np.round(step / self.period)  # unwrap: shortest periodic step
            for k, plane in enumerate(self.x_planes):
                if self.period is None:
                    crossings = (x1 >= plane).astype(np.int64) - (x0 >= plane)
                else:
                    crossings = np.floor((x1 - plane) / self.period) - np.floor((x0 - plane) / self.period)
                self.crossed_mass[k] += mass @ crossings
        self.previous, self.last_time = frame, time
        self.frames += 1

    def result(self) -> PlaneFlows:
        if self.frames < 2 or self.last_time <= self.first_time:
            raise AnalysisInputError("mass flow through planes needs at least two dump frames at different times")
        duration = self.last_time - self.first_time
        return PlaneFlows(self.x_planes, self.crossed_mass / duration * SECONDS_PER_HOUR, duration, self.frames)
