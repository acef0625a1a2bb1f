"""fix outlet/sink on exact kinematics: particles that pass the outlet plane x = X heading out of the
box sideways are removed within a step of passing it, counted with their mass, on 1 and 2 ranks; the
same particles without the sink leave the box and stop the run (lost atoms), which is why the open
cases use it; fix residence/time closes their records at its outlet plane."""
import math

import numpy as np
import pytest

from measure_cases import BASE, MASS, Mover, lanes, particles_include, read_records, variables, zones_text
from tsg_harness import run_lmp

DT = 1e-4
OUTLET = 0.08
STEPS = 2000
BOX_Y = 0.01     # measure_cases.BASE: the box is |y|, |z| <= 10 mm
OUT_OF_BOX = 20  # steps after passing X at which a particle left alone crosses y = BOX_Y


def movers() -> list[Mover]:
    return [Mover(0.002 + 0.0003 * k, 0.5 + 0.1 * k, *lane) for k, lane in enumerate(lanes(10))]


def sideways(m: Mover) -> float:
    """The y velocity that takes the particle's centre out of the box OUT_OF_BOX steps after it
    passes X (and not before: it stays inside the box up to there)."""
    return (BOX_Y - m.y) / ((OUTLET - m.x0) / m.v + OUT_OF_BOX * DT)


def particles(ms: list[Mover]) -> str:
    return particles_include(ms) + "".join(f"set atom {i} vy {sideways(m):.17g}\n" for i, m in enumerate(ms, start=1))


def sink_input(sink: bool) -> str:
    return (BASE + "include particles.include\nfix integr all nve/sphere\n"
            + "fix rt all residence/time zones zones.txt records records.txt inlet 0.005 outlet 0.079\n"
            + (f"fix out all outlet/sink x {OUTLET}\n" if sink else "")
            + f"timestep {DT}\n"
            + "thermo_style custom step atoms" + (" f_out[1] f_out[2]" if sink else "") + "\n"
            + f"thermo_modify lost error format float %.15g\nthermo 1\nrun {STEPS}\n")


def crossing_steps(ms: list[Mover]) -> np.ndarray:
    return np.array([math.ceil((OUTLET - m.x0) / m.v / DT) for m in ms])   # first step with x > X


@pytest.mark.parametrize("ranks", [1, 2])
def test_particles_past_the_outlet_are_removed_within_a_step_and_counted(tmp_path, ranks):
    ms = movers()
    run = run_lmp(sink_input(True), tmp_path, nprocs=ranks, variables=variables(False, px=ranks),
                  files={"zones.txt": zones_text(), "particles.include": particles(ms)})
    run.assert_clean()
    thermo = run.thermo[-1]
    crossed = crossing_steps(ms)
    assert crossed.max() < STEPS - 10, "every particle reaches the outlet in the run"
    steps, atoms = thermo["Step"].astype(int), thermo["Atoms"].astype(int)
    # a particle past X at the end of step n is deleted at step n + 1 (re-neighbouring, pre_exchange)
    upper = np.array([len(ms) - np.sum(crossed <= s - 2) for s in steps])
    lower = np.array([len(ms) - np.sum(crossed <= s) for s in steps])
    late = [(int(s), int(a), int(u)) for s, a, u in zip(steps, atoms, upper) if a > u]
    early = [(int(s), int(a), int(lo)) for s, a, lo in zip(steps, atoms, lower) if a < lo]
    assert not late and not early, f"(step, atoms, allowed): late {late[:3]} early {early[:3]}"
    assert run.last("out[1]") == len(ms) and run.last("Atoms") == 0
    assert run.last("out[2]") == pytest.approx(len(ms) * MASS, rel=1e-12)
    _, records = read_records(tmp_path / "records.txt")
    assert sorted(r.id for r in records) == list(range(1, len(ms) + 1))
    assert {r.reason for r in records} == {"outlet"}, "each crossed the residence outlet before the sink"
    print(f"[ measured ] {len(ms)} particles removed, each 1-2 steps after passing x = {OUTLET} m, {ranks} rank(s)")


def test_without_the_sink_the_same_particles_leave_the_box_and_stop_the_run(tmp_path):
    ms = movers()
    run = run_lmp(sink_input(False), tmp_path, variables=variables(False),
                  files={"zones.txt": zones_text(), "particles.include": particles(ms)}, expect_error=True)
    assert any("Lost atoms" in e for e in run.errors), run.errors
