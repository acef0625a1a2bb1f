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
        assert times[0] == pytest.approx(state.t_startup, rel=1e-5)
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
