"""The main job (scripts/main-job.sh, `./tsg run`) on a shortened window: three fills continued from
their kept states (cases/states/periodic-demo) end with numbers — mass flow at both sensors and
solid fraction per element resolved — and what the runs did is what the states say."""
import json
import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from tsg_analysis.liggghts_log import parse_thermo
from tsg_analysis.run import Run
from tsg_analysis.summary import combine_summaries, summarise
from tsg_cases import states

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
BUILD = Path(os.environ.get("TSG_BUILD_DIR", ROOT / "build"))
STATES = ROOT / "cases" / "states" / "periodic-demo"
SEEDS = (1, 2, 3)
SAMPLE = 0.1  # s per fill: long enough for sensor crossings in every fill, short enough for the suite


@pytest.fixture(scope="module")
def main_job(tmp_path_factory):
    out = tmp_path_factory.mktemp("main-job") / "periodic-demo"
    env = {**os.environ, "TSG_MAIN_SAMPLE": str(SAMPLE), "TSG_MAIN_OUT": str(out)}
    proc = subprocess.run([str(ROOT / "scripts" / "main-job.sh"), str(BUILD)], capture_output=True, text=True,
                          env=env, timeout=1500)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-4000:]
    return out, proc.stdout


def test_the_kept_states_describe_themselves():
    for seed in SEEDS:
        state = states.read(STATES / f"seed-{seed}")
        assert (state.case, state.scale, state.seed) == ("periodic", "demo", seed)
        assert state.t_startup == 1.5 and state.step > 0 and "write_state 1" in state.command
        assert state.time == pytest.approx(state.t_startup, rel=1e-5)   # carried by its restart file


def test_each_fill_continues_its_state_and_loses_nothing(main_job):
    out, _ = main_job
    for seed in SEEDS:
        run_dir = out / f"seed-{seed}"
        state = states.read(STATES / f"seed-{seed}")
        params = json.loads((run_dir / "params.json").read_text())
        assert params["seed"] == seed and params["from_state"]["step"] == state.step
        blocks = parse_thermo((run_dir / "log.lammps").read_text())
        steps = np.concatenate([b["Step"] for b in blocks])
        times = np.concatenate([b["Time"] for b in blocks])
        # the run starts at the state's step and time and samples SAMPLE s from there
        assert steps[0] == state.step
        assert times[0] == pytest.approx(state.time, rel=1e-6)
        assert times[-1] - times[0] == pytest.approx(SAMPLE, rel=0.02)
        count = int(re.search(r"fill_count equal (\d+)", (run_dir / "fill.vars").read_text()).group(1))
        assert all(np.all(b["Atoms"] == count) for b in blocks)
        assert "TSG-DONE escaped 0" in (run_dir / "log.lammps").read_text()


def test_the_summary_resolves_mass_flow_and_solid_fraction(main_job):
    out, stdout = main_job
    combined = combine_summaries([summarise(Run(out / f"seed-{seed}")) for seed in SEEDS])
    flows = {r.scope: r.estimate for r in combined.rows if r.quantity == "mass flow"}
    fractions = {r.scope: r.estimate for r in combined.rows if r.quantity == "solid fraction"}
    assert set(flows) >= {"sensor_1", "sensor_2"} and len(fractions) == 8
    for estimate in [*flows.values(), *fractions.values()]:
        assert estimate.resolved, estimate.text()
        assert estimate.half_width < abs(estimate.mean), estimate.text()   # a number, not an interval about 0
    # conservation: in a periodic domain both sensors see the same mean flux
    first, second = flows["sensor_1"], flows["sensor_2"]
    assert abs(first.mean - second.mean) <= first.half_width + second.half_width
    assert all(0.0 < e.mean < 0.74 for e in fractions.values())
    # what the user reads: the combined table, no "window too short" for these quantities
    table = stdout[stdout.index("the three fills combined"):]
    for line in table.splitlines():
        if line.strip().startswith(("sensor_", "C1", "K1")):
            assert "window too short" not in line and "too few replicas" not in line, line
    assert (out / "report" / "report.md").is_file() and (out / "summary.txt").is_file()


def test_a_state_continued_at_another_time_step_samples_the_planned_window(tmp_path):
    """The case plans its phases in time from the time the restart file carries: a state made at
    0.2 of the Rayleigh time, continued at 0.1, starts sampling at once (its start-up is over) and
    samples the planned window in twice as many steps of half the state's step (dt ∝ dt_fraction)."""
    sample, fraction = 0.002, 0.1
    state = states.read(STATES / "seed-1")
    out = tmp_path / "run"
    proc = subprocess.run([str(ROOT / ".venv" / "bin" / "tsg-run-case"), "periodic", "--scale", "demo", "--from-state",
                           str(state.path), "--np", "1", "--out", str(out), "-v", "t_sample", str(sample),
                           "-v", "dt_fraction", str(fraction), "-v", "thermo_every", "400", "-v", "stats_every", "400"],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    log = (out / "log.lammps").read_text()
    assert "without its simulation time" not in log
    blocks = parse_thermo(log)
    steps = np.concatenate([b["Step"] for b in blocks])
    times = np.concatenate([b["Time"] for b in blocks])
    state_dt = state.time / state.step            # the states ran at one time step from step 0
    dt = state_dt * fraction / 0.2                # the demo's 0.2 of the Rayleigh time, halved
    assert steps[0] == state.step and times[0] == pytest.approx(state.time, rel=1e-6)
    # the sampling ends at t_startup + t_sample, counted from the state's time
    assert steps[-1] - steps[0] == round((state.t_startup + sample - state.time) / dt)
    assert times[-1] == pytest.approx(state.t_startup + sample, abs=dt)


def test_a_state_without_its_time_is_refused(tmp_path):
    """A state made before restart files carried their time could only be continued at step x dt,
    wrong at another time step: it is refused with the command that makes it again."""
    old = tmp_path / "old-state"
    old.mkdir()
    description = json.loads((STATES / "seed-1" / "state.json").read_text())
    del description["time"]
    (old / "state.json").write_text(json.dumps(description))
    (old / "state.restart.xz").write_bytes(b"")
    (old / "fill.vars").write_text((STATES / "seed-1" / "fill.vars").read_text())
    with pytest.raises(states.StateError, match="before restart files carried their simulation time.*write_state 1"):
        states.read(old)
