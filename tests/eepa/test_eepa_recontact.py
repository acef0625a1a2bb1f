"""EEPA contacts start fresh (issue 14 item 4).

Two cohesive spheres collide head-on, separate, bounce off elastic Hertz walls and collide again.
A contact that re-forms must start virgin (docs/model.md, "Choice, separation"), whatever the
neighbour-list settings: the second impact's rebound must equal an independent integration of a
fresh contact (ReferenceContact, written from the formulas in docs/model.md) at the measured
approach speed. With the history of the first impact kept, the second rebound is 19 % faster
(worked out in `stale_history_changes_the_rebound` below), so the check can fail.
"""
from __future__ import annotations

import numpy as np
import pytest

from tsg_harness import run_lmp

from tsg_cases.eepa_contact import INPUTS, MASS, Eepa, ReferenceContact

# cohesive and plastic, undamped (e = 1) so that the walls return the spheres at the speed they
# left with and the only dissipation is EEPA hysteresis and adhesion
LAW = Eepa(plasticity_ratio=0.6, surface_energy=3.0, tension_exponent=4.0, restitution=1.0)
SPEED = 0.02          # m/s, each sphere, first impact
WALL_GAP = 1.0e-4     # m, from each sphere's outer surface to its wall at the start
TIMESTEP = 1.0e-6     # s, 1/250 of the contact time
NSTEPS = 26000        # first impact, wall bounce, second impact, apart again (checked below)

NEIGHBOUR_SETTINGS = {
    # LIGGGHTS' defaults: the list is not rebuilt between the two impacts (max displacement
    # 0.1 mm < skin/2 = 0.25 mm), so the pair's history slot survives the separation
    "default": "neigh_modify every 1 delay 10 check yes",
    "rebuild-every-step": "neigh_modify every 1 delay 0 check no",
    "contact-distance-factor": "neigh_modify contact_distance_factor 1.01",
}


def reference_rebound(approach: float, contact: ReferenceContact, keep_history: bool = False) -> float:
    """Relative rebound speed of a head-on impact at relative speed `approach`: velocity Verlet on
    the relative coordinate, m* d²δ/dt² = -F(δ), with 4000 steps per δmax/approach (about 1/12 000
    of the contact time). keep_history: the contact remembers its history through δ <= 0 (the
    behaviour the test guards against)."""
    reduced_mass = MASS / 2
    max_overlap = (5 * reduced_mass * approach**2 / (4 * contact.k1)) ** 0.4   # Hertz estimate
    dt = max_overlap / approach / 4000
    overlap, rate, force = 0.0, approach, 0.0
    for _ in range(10**7):
        rate -= force / reduced_mass * dt / 2
        overlap += rate * dt
        force = 0.0 if (keep_history and overlap <= 0) else contact.force(overlap)
        rate -= force / reduced_mass * dt / 2
        if overlap < 0 and rate < 0:
            return -rate
    raise AssertionError("reference impact did not separate")


def test_stale_history_changes_the_rebound():
    """The test below can fail: with the first impact's history kept, the second rebound differs
    from a fresh contact's by far more than the tolerance."""
    contact = ReferenceContact(LAW)
    first = reference_rebound(2 * SPEED, contact, keep_history=True)
    fresh = reference_rebound(first, ReferenceContact(LAW))
    stale = reference_rebound(first, contact, keep_history=True)
    assert stale / fresh - 1 > 0.1


def two_impacts_input(neighbour: str) -> tuple[str, dict]:
    text = (INPUTS / "in.two_sphere_impact").read_text()
    text = text.replace("thermo_style custom step atoms ke v_gap v_v1 v_v2",
                        "variable x1 equal x[1]\nvariable x2 equal x[2]\n"
                        "thermo_style custom step atoms ke v_gap v_v1 v_v2 v_x1 v_x2")
    text = text.replace("thermo 100", "thermo 20")
    wall = 0.002002 + WALL_GAP
    walls = (f"fix wall_left all wall/gran model hertz tangential history primitive type 1 xplane {-wall!r}\n"
             f"fix wall_right all wall/gran model hertz tangential history primitive type 1 xplane {wall!r}\n"
             f"{neighbour}\n")
    return text, {"model.include": LAW.include(walls=walls)}


@pytest.mark.parametrize("setting", NEIGHBOUR_SETTINGS)
def test_second_impact_rebounds_like_a_fresh_contact(tmp_path, setting):
    text, files = two_impacts_input(NEIGHBOUR_SETTINGS[setting])
    run = run_lmp(text, tmp_path, variables={"v": SPEED, "nsteps": NSTEPS, "dt": TIMESTEP}, files=files)
    run.assert_clean()
    thermo = run.thermo[-1]
    gap, v1, v2, x1 = thermo["gap"], thermo["v1"], thermo["v2"], thermo["x1"]
    wall = 0.002002 + WALL_GAP
    touching = gap <= 0
    at_wall = x1 - 0.001 <= -wall
    # phases, from the positions: impact 1, flight, wall, flight, impact 2, apart
    starts = np.flatnonzero(np.diff(touching.astype(int)) == 1) + 1
    ends = np.flatnonzero(np.diff(touching.astype(int)) == -1) + 1
    assert len(starts) == 2 and len(ends) == 2, (starts, ends)
    assert np.any(at_wall[ends[0]:starts[1]]), "sphere 1 did not reach its wall between the impacts"
    assert not np.any(at_wall[ends[1]:]), "run too long: sphere 1 reached its wall again"
    # symmetric motion: the pair's centre stays at rest
    np.testing.assert_allclose(v1 + v2, 0, atol=1e-9 * SPEED)

    # first impact: a fresh contact at the set speed
    first_rebound = (v2[ends[0]] - v1[ends[0]])
    assert first_rebound == pytest.approx(reference_rebound(2 * SPEED, ReferenceContact(LAW)), rel=1e-3)
    # second impact: approach measured in free flight just before it, then a fresh contact
    approach = v1[starts[1] - 1] - v2[starts[1] - 1]
    assert approach == pytest.approx(first_rebound, rel=1e-3)   # the walls are elastic
    second_rebound = v2[-1] - v1[-1]
    expected = reference_rebound(approach, ReferenceContact(LAW))
    assert second_rebound == pytest.approx(expected, rel=1e-3), (
        f"second rebound {second_rebound:.6g} m/s, fresh contact {expected:.6g} m/s")
