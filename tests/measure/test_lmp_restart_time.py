"""The simulation time survives a restart (patches/write-restart-cpp.patch, read-restart-cpp.patch,
integrate-cpp.patch): upstream LIGGGHTS 3.8 started it again from 0 after read_restart, so the log of
a continued run (a job segment, a run from a kept state) gave times since the restart. The time is
compared with its closed form Σ steps × dt over runs with two different time steps, which step ×
dt of the last step (the fallback for a file written without its time) does not give."""
from __future__ import annotations

import pytest
from crafted_scenes import MATERIAL, header, setup
from tsg_harness import run_lmp

# after the material: the integrator, gravity, and the time in thermo
MOTION = """fix integrate all nve/sphere
fix gravity all gravity 9.81 vector 0 0 -1
thermo_style custom step time atoms
thermo_modify format float %.15g
thermo 10
"""
DT_FIRST, STEPS_FIRST = 1e-5, 100
DT_SECOND, STEPS_SECOND = 4e-6, 50


def first_rows(log_rows):
    return [(int(b["Step"][0]), float(b["Time"][0])) for b in log_rows]


@pytest.mark.parametrize("nprocs", [1, 2])
def test_a_continued_run_reports_the_time_since_its_start(tmp_path, nprocs):
    written = run_lmp(header() + "create_atoms 1 single 0 0 0 units box\n"
                      "create_atoms 1 single 0.005 0 0 units box\nset group all diameter 0.001 density 2500\n"
                      + MOTION + f"timestep {DT_FIRST}\nrun {STEPS_FIRST}\ntimestep {DT_SECOND}\nrun {STEPS_SECOND}\n"
                      "write_restart state.restart\n", tmp_path, nprocs=nprocs)
    time_written = STEPS_FIRST * DT_FIRST + STEPS_SECOND * DT_SECOND
    assert written.last("Time") == pytest.approx(time_written, rel=1e-12)
    continued = run_lmp(setup() + "read_restart state.restart\n" + MATERIAL + MOTION + f"timestep {DT_SECOND}\nrun 20\n",
                        tmp_path, nprocs=nprocs, input_name="in.continued")
    step, time = first_rows(continued.thermo)[0]
    assert step == STEPS_FIRST + STEPS_SECOND
    assert time == pytest.approx(time_written, rel=1e-12)            # not 0 (upstream), not step x dt
    assert time != pytest.approx(step * DT_SECOND, rel=1e-3)
    assert continued.last("Time") == pytest.approx(time_written + 20 * DT_SECOND, rel=1e-12)
    assert not [w for w in continued.warnings if "without its simulation time" in w]
