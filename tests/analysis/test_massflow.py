"""Steady-state decision from prescribed sensor flows, and mass flow of prescribed plane crossings."""
import numpy as np
import pytest

from tsg_analysis.dumps import ParticleFrame
from tsg_analysis.massflow import (PlaneFlowCounter, decide_steady_state, sensor_flows, step_clock, window_means)
from tsg_analysis.run_files import AnalysisInputError, MassFlowRecord

DT = 1e-6


def record(time, *sensors):
    time = np.asarray(time, dtype=float)
    return MassFlowRecord(np.round(time / DT).astype(np.int64), time, np.column_stack(sensors),
                          tuple(f"sensor_{k + 1}" for k in range(len(sensors))))


def test_window_means_are_time_weighted():
    time = np.arange(1, 21) * 0.01  # 20 rows of 10 ms
    flow = np.where(time <= 0.1, 2.0, 4.0)
    starts, means = window_means(record(time, flow, flow), 0.1)
    np.testing.assert_allclose(starts, [0.0, 0.1])
    np.testing.assert_allclose(means[:, 0], [2.0, 4.0])


def test_steady_from_where_outlet_meets_inlet():
    time = np.arange(1, 1001) * 1e-3  # 1 s
    inlet = np.full_like(time, 14.4)
    outlet = np.where(time <= 0.4, 0.0, 14.4)  # nothing arrives before 0.4 s
    steady = decide_steady_state(record(time, inlet, 0.5 * (inlet + outlet), outlet), window=0.1)
    assert steady.reached and steady.start_time == pytest.approx(0.4)
    assert "steady from t = 0.4 s" in steady.message
    flows = sensor_flows(record(time, inlet, outlet), steady.start_time, steady.end_time)
    np.testing.assert_allclose([e.mean for e in flows.values()], [14.4, 14.4])
    np.testing.assert_allclose([e.half_width for e in flows.values()], [0.0, 0.0], atol=1e-12)
    assert flows["sensor_2"].chosen_start == pytest.approx(0.4005)  # middle of the first row in the window
    assert flows["sensor_2"].detected_start == pytest.approx(0.4005, abs=0.006)  # the outlet's jump, found


def test_outlet_that_never_catches_up_is_not_steady():
    time = np.arange(1, 1001) * 1e-3
    steady = decide_steady_state(record(time, np.full_like(time, 14.4), np.full_like(time, 13.0)), window=0.1)
    assert not steady.reached and steady.start_time is None
    assert "never reached steady state" in steady.message and "9.7%" in steady.message


def test_tolerance_is_relative_to_the_inlet():
    time = np.arange(1, 1001) * 1e-3
    inlet, outlet = np.full_like(time, 10.0), np.full_like(time, 10.4)
    assert decide_steady_state(record(time, inlet, outlet), 0.1, tolerance=0.05).reached
    assert not decide_steady_state(record(time, inlet, outlet), 0.1, tolerance=0.03).reached


def test_empty_granulator_is_not_steady():
    time = np.arange(1, 1001) * 1e-3
    steady = decide_steady_state(record(time, np.zeros_like(time), np.zeros_like(time)), 0.1)
    assert not steady.reached and "no forward flow" in steady.message


def test_short_record_and_single_sensor_cannot_decide():
    time = np.arange(1, 101) * 1e-3
    assert "shorter than 2 windows" in decide_steady_state(record(time, time, time), window=0.1).message
    assert "single sensor" in decide_steady_state(record(time, time), 0.1).message


def test_step_clock_maps_steps_to_time():
    clock = step_clock(record(1.0 + np.arange(1, 11) * 1e-3, np.ones(10), np.ones(10)))
    assert clock.dt == pytest.approx(DT)
    assert float(clock.time(round(1.005 / DT))) == pytest.approx(1.005)
    assert clock.step(1.002) == pytest.approx(1.002 / DT)


def frame(step, ids, x, mass=None):
    columns = {"id": np.asarray(ids), "x": np.asarray(x, dtype=float)}
    if mass is not None:
        columns["mass"] = np.asarray(mass, dtype=float)
    return ParticleFrame(step, columns)


def test_prescribed_crossings_give_their_mass_flow():
    mass = 1e-6  # kg
    # ids 1-10 cross x = 0.05 forward, 11-13 backward, 14-18 stay upstream; 19 leaves, 20 is new
    ids0 = np.arange(1, 20)
    x0 = np.concatenate([np.full(10, 0.04), np.full(3, 0.06), np.full(5, 0.01), [0.04]])
    ids1 = np.concatenate([np.arange(1, 19), [20]])
    x1 = np.concatenate([np.full(10, 0.06), np.full(3, 0.04), np.full(5, 0.02), [0.06]])
    counter = PlaneFlowCounter(np.array([0.05, 0.015]))
    counter.add(frame(0, ids0, x0, np.full(19, mass)), 0.0)
    counter.add(frame(1, ids1, x1, np.full(19, mass)), 0.1)
    flows = counter.result()
    np.testing.assert_allclose(flows.flow, [(10 - 3) * mass / 0.1 * 3600, 5 * mass / 0.1 * 3600])
    assert flows.frames == 2 and flows.duration == pytest.approx(0.1)


def test_periodic_wrap_counts_as_one_pass():
    counter = PlaneFlowCounter(np.array([0.0, 0.05, 0.1]), period=0.1)
    counter.add(frame(0, [1, 2], [0.095, 0.049], [1.0, 2.0]), 0.0)
    counter.add(frame(1, [1, 2], [0.002, 0.051], [1.0, 2.0]), 1.0)  # 1 wraps forward, 2 crosses the middle
    np.testing.assert_allclose(counter.result().flow, np.array([1.0, 2.0, 1.0]) * 3600)


def test_density_replaces_a_missing_mass_column():
    radius = 1e-3
    counter = PlaneFlowCounter(np.array([0.5]), density=1000.0)
    for step, x in ((0, 0.4), (1, 0.6)):
        counter.add(ParticleFrame(step, {"id": np.array([1]), "x": np.array([x]), "radius": np.array([radius])}), step)
    assert counter.result().flow[0] == pytest.approx(1000.0 * 4 / 3 * np.pi * radius**3 * 3600)
    without = PlaneFlowCounter(np.array([0.5]))
    without.add(frame(0, [1], [0.4]), 0.0)
    with pytest.raises(AnalysisInputError, match="no 'mass' column"):
        without.add(frame(1, [1], [0.6]), 1.0)


def test_one_frame_is_not_enough():
    counter = PlaneFlowCounter(np.array([0.5]))
    counter.add(frame(0, [1], [0.4], [1.0]), 0.0)
    with pytest.raises(AnalysisInputError, match="at least two dump frames"):
        counter.result()
