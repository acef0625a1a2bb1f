"""fix squeeze/ledger on crafted scenes (docs/stability.md, "Squeezes on the paper machine"): a
sphere driven into a wedge of two fixed walls and out again is one squeeze event whose peak overlap
is the wedge's closed form, also when it changes rank mid-event; two spheres pressed into each other
are one event each with the closed-form pair overlap, with the Hertz and the EEPA pair models, also
across two ranks; a centre pushed through a wall is
counted, named, and stops the run above max_crossed; gravity's work equals m g Δz; an elastic
collision at a safe step creates no energy, one at ten times the critical step stops the run."""
from __future__ import annotations

import math

import numpy as np
import pytest
from crafted_scenes import (
    ALPHA,
    DENSITY,
    LOW_DISC,
    PLANE,
    POISSON,
    RADIUS,
    RAYLEIGH,
    TIMESTEP,
    WEDGE_A,
    WEDGE_B,
    YOUNGS,
    corotating_walls,
    header,
)
from tsg_harness import run_lmp

from tsg_cases.eepa_contact import Eepa

MASS = DENSITY * 4 / 3 * math.pi * RADIUS**3
HEADER = header(processors="* 1 1")
# the ledger's vector as thermo columns q1 .. q13 (LIGGGHTS cuts column names to 8 characters)
THERMO = "".join(f"variable q{k} equal f_squeeze[{k}]\n" for k in range(1, 14)) + \
    "thermo_style custom step atoms " + " ".join(f"v_q{k}" for k in range(1, 14)) + \
    "\nthermo_modify format float %.15g norm no\n"
S = math.sin(ALPHA)


def ledger(keys: str = "") -> str:
    return f"fix squeeze all squeeze/ledger walls walls records squeezes.txt {keys}\n"


def read_records(path) -> np.ndarray:
    return np.atleast_2d(np.loadtxt(path, comments="#", ndmin=2))


# the wedge squeeze: pushed down at PUSH for N_IN steps, then back up for N_OUT, drifting along x
# across the middle of the box (the boundary between 2 ranks) while squeezed
Z0 = 1.01 * RADIUS / S      # m, 1 % above first touch
PUSH, DRIFT = 0.1, 0.05     # m/s
N_IN, N_OUT = 5000, 5000
X0 = -0.0003                # m: at x = 0 after 6000 steps


def wedge_heights(steps: np.ndarray) -> np.ndarray:
    up = np.clip(steps - N_IN, 0, None)
    return Z0 - PUSH * TIMESTEP * (np.minimum(steps, N_IN) - up)


def wedge_scene() -> str:
    return HEADER + corotating_walls(["wall_a", "wall_b"]) + f"""create_atoms 1 single {X0!r} 0 {Z0!r} units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
timestep {TIMESTEP!r}
{ledger()}{THERMO}thermo 1000
fix push all move linear {DRIFT!r} 0 -{PUSH!r}
run {N_IN}
unfix push
fix pull all move linear {DRIFT!r} 0 {PUSH!r}
run {N_OUT}
"""


@pytest.mark.parametrize("nprocs", [1, 2])
def test_a_sphere_driven_into_a_wedge_is_one_squeeze_with_the_closed_form_peak(tmp_path, nprocs):
    run = run_lmp(wedge_scene(), tmp_path, nprocs=nprocs, files={"wall_a.stl": WEDGE_A, "wall_b.stl": WEDGE_B,
                                                                   "disc.stl": LOW_DISC})
    thermo = run.thermo[-1]
    records = read_records(tmp_path / "squeezes.txt")
    assert records.shape == (1, 15), records
    assert thermo["q1"][-1] == 1 and thermo["q3"][-1] == 1    # one event, one particle
    (t_start, t_end, ident, x, _, z, radius, peak_wall, peak_pair, wall_bits, kind, with_particles, start_speed,
     release_speed, number) = records[0]
    steps = np.arange(N_IN + N_OUT + 1)
    depth = 1 - wedge_heights(steps) * S / RADIUS         # δ/R against each wall, closed form
    # the deepest step is the last push step; positions are x0 + v t to rounding (1e-12 m here), so δ/R
    # is exact to 1e-9
    assert peak_wall == pytest.approx(depth.max(), abs=1e-9)
    assert peak_wall == pytest.approx(1 - (Z0 - PUSH * TIMESTEP * N_IN) * S / RADIUS, abs=1e-9)
    first = int(steps[depth > 0.1][0])
    assert t_start == pytest.approx(first * TIMESTEP, rel=1e-9)
    closed = int(steps[(steps > N_IN) & (depth < 0.05)][0])
    assert t_end == pytest.approx((closed + 50) * TIMESTEP, rel=1e-9)  # 50 release steps after the end
    assert z == pytest.approx(Z0 - PUSH * TIMESTEP * N_IN, abs=1e-12)
    assert x == pytest.approx(X0 + DRIFT * TIMESTEP * N_IN, abs=1e-12)
    assert x < 0 < X0 + DRIFT * TIMESTEP * closed          # the event crossed the rank boundary x = 0
    assert ident == 1 and radius == pytest.approx(RADIUS) and number == 1
    assert peak_pair == 0 and with_particles == 0
    assert wall_bits == 3 and kind == 0                     # both walls: two_walls
    speed = math.hypot(PUSH, DRIFT)                          # prescribed
    assert start_speed == pytest.approx(speed, rel=1e-9) and release_speed == pytest.approx(speed, rel=1e-9)
    assert thermo["q7"][-1] == 0                  # no centre behind a wall
    assert thermo["q8"][-1] == 0                  # fixed walls do no work


# two spheres pressed into each other along x (prescribed, fix move), across the rank boundary x = 0,
# far above the plane: the pair overlap alone opens the event
GAP0 = 0.01 * RADIUS        # m, apart at the start
APPROACH = 0.1              # m/s, each sphere
N_PRESS = 1600              # steps in, then as many out: closest at 2 R + GAP0 − 2 APPROACH dt N_PRESS
PAIR_PEAK = (2 * APPROACH * TIMESTEP * N_PRESS - GAP0) / RADIUS   # δ/R at the closest, 0.31
PAIR_MODELS = {"hertz": "pair_style gran model hertz tangential history\npair_coeff * *\n",
               "eepa": "\n".join(line for line in Eepa().include().splitlines() if not line.startswith("fix m3 ")) + "\n"}


def pressed_pair_scene(model: str) -> str:
    header = HEADER.replace("pair_style gran model hertz tangential history\npair_coeff * *\n", PAIR_MODELS[model])
    x0 = RADIUS + GAP0 / 2
    return header + corotating_walls(["plane"]) + f"""create_atoms 1 single {-x0!r} 0 0.005 units box
create_atoms 1 single {x0!r} 0 0.005 units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
group left id 1
group right id 2
timestep {TIMESTEP!r}
{ledger()}{THERMO}thermo 400
fix in_left left move linear {APPROACH!r} 0 0
fix in_right right move linear -{APPROACH!r} 0 0
run {N_PRESS}
unfix in_left
unfix in_right
fix out_left left move linear -{APPROACH!r} 0 0
fix out_right right move linear {APPROACH!r} 0 0
run {N_PRESS}
"""


@pytest.mark.parametrize("nprocs", [1, 2])
@pytest.mark.parametrize("model", sorted(PAIR_MODELS))
def test_two_spheres_pressed_together_are_one_squeeze_each_with_the_closed_form_pair_peak(tmp_path, model, nprocs):
    run = run_lmp(pressed_pair_scene(model), tmp_path, nprocs=nprocs, files={"plane.stl": PLANE, "disc.stl": LOW_DISC})
    records = read_records(tmp_path / "squeezes.txt")
    assert records.shape == (2, 15), records
    thermo = run.thermo[-1]
    assert thermo["q1"][-1] == 2 and thermo["q3"][-1] == 2
    assert thermo["q5"][-1] == pytest.approx(PAIR_PEAK, abs=1e-9)
    for record in records:
        ident, x, peak_wall, peak_pair, kind, with_particles = record[[2, 3, 7, 8, 10, 11]]
        # positions are x0 + v t to rounding (1e-12 m): δ/R exact to 1e-9
        assert peak_pair == pytest.approx(PAIR_PEAK, abs=1e-9)
        assert peak_wall == 0 and with_particles == 1 and kind == 3        # particles alone
        closest = RADIUS + GAP0 / 2 - APPROACH * TIMESTEP * N_PRESS
        assert x == pytest.approx(-closest if ident == 1 else closest, abs=1e-12)


def test_a_pair_style_that_does_not_record_the_pair_depths_is_refused(tmp_path):
    # the granular pair style records each particle's deepest overlap in its force pass; switched off,
    # the ledger would see no particle contact at all
    text = HEADER.replace("pair_coeff * *\n", "pair_coeff * *\npair_modify compute no\n") + corotating_walls(["plane"]) + \
        f"create_atoms 1 single 0 0 0.005 units box\n{ledger()}run 1\n"
    run = run_lmp(text, tmp_path, files={"plane.stl": PLANE, "disc.stl": LOW_DISC}, expect_error=True)
    assert "fix squeeze squeeze/ledger: pair style 'gran' does not record each particle's deepest particle-particle " \
        "overlap (allowed: pair_style gran, with its force computation on)" in run.log, run.log[-1500:]


def pushed_through_plane(keys: str) -> str:
    return HEADER + corotating_walls(["plane"]) + f"""create_atoms 1 single 0.0003 0.0002 {1.01 * RADIUS!r} units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
timestep {TIMESTEP!r}
{ledger(keys)}{THERMO}thermo 1000
fix push all move linear 0 0 -0.1
run 12000
"""


@pytest.mark.parametrize("nprocs", [1, 2])
def test_a_centre_pushed_through_a_wall_is_counted_and_named(tmp_path, nprocs):
    run = run_lmp(pushed_through_plane(""), tmp_path, nprocs=nprocs, files={"plane.stl": PLANE, "disc.stl": LOW_DISC})
    assert run.last("q7") == 1, run.log[-2000:]
    first = int(np.ceil(1.01 * RADIUS / (0.1 * TIMESTEP) + 1e-9))     # the first step with the centre below z = 0
    assert "fix squeeze squeeze/ledger: crossing 1: particle 1 has its centre behind the surface of wall plane" in run.log
    assert f"t = {first * TIMESTEP:.10g} s" in run.log or f"t = {(first + 1) * TIMESTEP:.10g} s" in run.log, run.log[-2000:]


def test_a_crossing_above_max_crossed_stops_the_run(tmp_path):
    run = run_lmp(pushed_through_plane("max_crossed 0"), tmp_path, files={"plane.stl": PLANE, "disc.stl": LOW_DISC},
                  expect_error=True)
    assert "particle 1 has its centre behind the surface of wall plane" in run.log
    assert "1 crossings exceed max_crossed = 0" in run.log, run.log[-2000:]


def test_gravity_work_is_m_g_dz_and_creates_no_excess(tmp_path):
    text = HEADER + corotating_walls(["plane"]) + f"""create_atoms 1 single 0.0003 0.0002 0.008 units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
velocity all set 0.01 0 0.2 units box
fix integrate all nve/sphere
fix gravity all gravity 9.81 vector 0 0 -1
timestep {TIMESTEP!r}
{ledger()}variable z equal z[1]
{THERMO}thermo_style custom step v_z v_q9 v_q10 v_q12
thermo_modify format float %.15g norm no
thermo 500
run 20000
"""
    run = run_lmp(text, tmp_path, files={"plane.stl": PLANE, "disc.stl": LOW_DISC})
    thermo = run.thermo[-1]
    np.testing.assert_allclose(thermo["q9"], MASS * 9.81 * (0.008 - thermo["z"]), rtol=1e-9, atol=1e-18)
    kinetic = 0.5 * MASS * (0.01**2 + 0.2**2) + MASS * 9.81 * (0.008 - thermo["z"])
    np.testing.assert_allclose(thermo["q10"], kinetic, rtol=1e-9)
    assert np.all(np.abs(thermo["q12"]) < 1e-9)


def head_on(dt: float, keys: str) -> str:
    return HEADER + corotating_walls(["plane"]) + f"""create_atoms 1 single -0.0011 0 0.005 units box
create_atoms 1 single  0.0011 0 0.005 units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
velocity all set NULL 0 0 units box
set atom 1 vx 0.5
set atom 2 vx -0.5
fix integrate all nve/sphere
timestep {dt!r}
{ledger(keys)}{THERMO}thermo 10
run {int(round(4e-3 / dt))}
"""


def test_an_elastic_collision_at_a_safe_step_conserves_the_budget(tmp_path):
    run = run_lmp(head_on(0.1 * RAYLEIGH, "max_energy_excess 0.05"), tmp_path, files={"plane.stl": PLANE, "disc.stl": LOW_DISC})
    thermo = run.thermo[-1]
    assert thermo["q10"][-1] == pytest.approx(2 * 0.5 * MASS * 0.25, rel=1e-3)   # e = 1: all back
    assert np.all(thermo["q12"] < 1e-3)
    assert thermo["q12"].min() < -0.01             # while in contact the energy is stored


@pytest.mark.parametrize("nprocs", [1, 2])
def test_energy_created_by_a_far_too_long_step_stops_the_run(tmp_path, nprocs):
    run = run_lmp(head_on(10 * RAYLEIGH, "max_energy_excess 0.05"), tmp_path, nprocs=nprocs,
                  files={"plane.stl": PLANE, "disc.stl": LOW_DISC}, expect_error=True)
    assert "fix squeeze squeeze/ledger: kinetic energy runaway" in run.log, run.log[-2000:]
    assert "above max_energy_excess = 0.05; fastest particle" in run.log
    assert "reduce the time step" in run.log


def yield_rebound_speed(modulus: float, radius: float, pressure: float, mass: float, speed: float) -> float:
    """Closed form of the yield-limited wall contact (Thornton & Ning 1998, physics/yield_law.h),
    written out again here: a head-on impact at `speed` loads to δ_max, the Hertzian unloading about
    the enlarged radius gives back (2/5) F_max (δ_max − δ_p)."""
    dy = radius * (math.pi * pressure / (2 * modulus)) ** 2
    fy = 4 / 3 * modulus * math.sqrt(radius) * dy**1.5
    energy = 0.5 * mass * speed**2
    k = math.pi * pressure * radius   # 0.4 fy dy + fy x + k x^2 / 2 = energy
    dmax = dy + (-fy + math.sqrt(fy**2 + 2 * k * (energy - 0.4 * fy * dy))) / k
    fmax = fy + k * (dmax - dy)
    a = math.sqrt((2 * fmax + fy) / (2 * math.pi * pressure))
    plastic = dmax - 3 * fmax / (4 * modulus * a)
    return math.sqrt(2 * 0.4 * fmax * (dmax - plastic) / mass)


@pytest.mark.parametrize("nprocs", [1, 2])
def test_with_the_yield_treatment_a_crushed_sphere_leaves_at_the_closed_form_speed(tmp_path, nprocs):
    pressure, impact = 1.0e6, 5.0      # Pa, m/s: yields at 0.35 % of R, peaks near 0.29 R
    text = HEADER.replace("pair_style gran model hertz", "fix m5 all property/global yieldPressure peratomtypepair 1 "
                          f"{pressure!r}\npair_style gran model hertz") \
        + corotating_walls(["plane"]).replace("model hertz", "model yield") \
        + f"""create_atoms 1 single 0.0003 0.0002 {1.001 * RADIUS!r} units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
velocity all set 0 0 -{impact!r} units box
fix integrate all nve/sphere
timestep {TIMESTEP!r}
{ledger()}{THERMO}thermo 100
run 3000
"""
    run = run_lmp(text, tmp_path, nprocs=nprocs, files={"plane.stl": PLANE, "disc.stl": LOW_DISC})
    records = read_records(tmp_path / "squeezes.txt")
    assert records.shape == (1, 15), records
    modulus = YOUNGS / (2 * (1 - POISSON**2))          # E* of two equal materials
    expected = yield_rebound_speed(modulus, RADIUS, pressure, MASS, impact)
    # coefficientRestitution 1: no dashpot; the integration error at 1e-6 s is far below 0.5 %
    assert records[0, 13] == pytest.approx(expected, rel=5e-3)
    assert expected < 0.4 * impact                     # most of the impact energy is dissipated (87 %)
    assert records[0, 7] > 0.2 and records[0, 10] == 2  # a deep contact with one wall: wall_alone
    hertz_peak = (15 * MASS * impact**2 / (16 * modulus * math.sqrt(RADIUS))) ** 0.4 / RADIUS
    assert records[0, 7] > hertz_peak                  # the yielding contact goes deeper than Hertz
    assert run.last("q10") == pytest.approx(0.5 * MASS * expected**2, rel=1e-2)


def test_a_yield_pressure_that_is_not_positive_is_refused(tmp_path):
    text = HEADER.replace("pair_style gran model hertz", "fix m5 all property/global yieldPressure peratomtypepair 1 "
                          "-5\npair_style gran model hertz") + corotating_walls(["plane"]).replace("model hertz", "model yield") + \
        "run 1\n"
    run = run_lmp(text, tmp_path, files={"plane.stl": PLANE, "disc.stl": LOW_DISC}, expect_error=True)
    assert "model yield, atom types 1 1: yieldPressure = -5" in run.log and "(0, inf) Pa" in run.log, run.log[-1500:]
