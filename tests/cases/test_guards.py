"""Guards that stop a bad run and the wall-overlap monitor of fix check/contact (issue 14 items 2
and 3). Each guard fires on a crafted input with a message naming what happened and where, at the
step an independent calculation predicts; a run within safe settings never trips them."""
from __future__ import annotations

import math
import os
import subprocess

import numpy as np
import pytest
from crafted_scenes import (
    DENSITY,
    HEADER,
    PLANE,
    POISSON,
    RADIUS,
    RANK_ONE_GUARDS,
    RAYLEIGH,
    TIMESTEP,
    YOUNGS,
    stl,
)
from tsg_harness import lmp_executable, mpi_command, run_lmp

# the plane z = 0 the particle is pushed into (PLANE), and a small disc far away that turns about x (a
# wall/gran/corotating fix needs one turning mesh)
DISC = stl("disc", [((-0.008, -0.001, -0.001), (-0.008, 0.001, -0.001), (-0.008, 0.001, 0.001)),
                    ((-0.008, -0.001, -0.001), (-0.008, 0.001, 0.001), (-0.008, -0.001, 0.001))])
WALL_PATHS = {
    "stock": "fix walls all wall/gran model hertz tangential history mesh n_meshes 2 meshes plane disc",
    "corotating": "fix walls all wall/gran/corotating model hertz tangential history mesh n_meshes 2 meshes plane disc "
                  "fixed plane corotate disc origin 0 0 0 axis 1 0 0 period 1",
}
PUSH_SPEED = 0.1      # m/s, prescribed (fix move): no contact force can stop the particle
START_GAP = 1.05e-5   # m, between the particle and the plane at step 0


def pushed_into_plane(path: str, guard: str, nsteps: int) -> tuple[str, dict]:
    text = HEADER + f"""fix plane all mesh/surface file plane.stl type 1
fix disc all mesh/surface file disc.stl type 1
{WALL_PATHS[path]}
create_atoms 1 single 0.0003 0.0002 {RADIUS + START_GAP!r} units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
fix push all move linear 0 0 -{PUSH_SPEED!r}
timestep {TIMESTEP!r}
fix check all check/contact every 10 walls walls {guard}
thermo_style custom step atoms f_check[5] f_check[6] f_check[7]
thermo_modify format float %.15g norm no
thermo 10
run {nsteps}
"""
    return text, {"plane.stl": PLANE, "disc.stl": DISC}


def wall_overlap_ratio(step: np.ndarray) -> np.ndarray:
    """δ/R of the pushed particle at a step: it moves PUSH_SPEED · t towards the plane."""
    return np.maximum(0.0, PUSH_SPEED * step * TIMESTEP - START_GAP) / RADIUS


@pytest.mark.parametrize("path", WALL_PATHS)
def test_wall_overlap_monitor_reads_the_overlap_of_each_mesh(tmp_path, path):
    text, files = pushed_into_plane(path, "", 3000)
    run = run_lmp(text, tmp_path, files=files)
    thermo = run.thermo[-1]
    np.testing.assert_allclose(thermo["check[6]"], wall_overlap_ratio(thermo["Step"]), rtol=1e-9, atol=1e-12)
    assert thermo["check[6]"][-1] > 0.25
    np.testing.assert_array_equal(thermo["check[7]"], 0.0)   # nothing touches the disc
    # largest speed since the previous check (fix move sets it from the first step on)
    np.testing.assert_allclose(thermo["check[5]"][1:], PUSH_SPEED, rtol=1e-12)


@pytest.mark.parametrize("path,nprocs", [("stock", 1), ("corotating", 1), ("stock", 2), ("corotating", 2)])
def test_particle_pushed_into_a_wall_stops_the_run(tmp_path, path, nprocs):
    threshold = 0.3
    text, files = pushed_into_plane(path, f"max_wall_overlap {threshold}", 5000)
    run = run_lmp(text, tmp_path, files=files, nprocs=nprocs, expect_error=True)
    # first check (every 10 steps) above the threshold
    steps = np.arange(0, 5001, 10)
    first = int(steps[wall_overlap_ratio(steps) > threshold][0])
    expected = (f"check/contact: step {first}: particle 1 overlaps mesh plane by "
                f"{wall_overlap_ratio(np.array([first]))[0]:.4g} of its radius, above max_wall_overlap = 0.3")
    assert expected in run.log, run.log[-2000:]


def test_pair_overlap_guard_names_both_particles(tmp_path):
    text = HEADER + f"""create_atoms 1 single -{RADIUS + START_GAP!r} 0 0 units box
create_atoms 1 single  {RADIUS + START_GAP!r} 0 0 units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
group left id 1
group right id 2
fix push_left left move linear {PUSH_SPEED!r} 0 0
fix push_right right move linear -{PUSH_SPEED!r} 0 0
timestep {TIMESTEP!r}
fix check all check/contact every 10 max_pair_overlap 0.5
thermo 10
run 5000
"""
    run = run_lmp(text, tmp_path, expect_error=True)
    steps = np.arange(0, 5001, 10)
    ratio = np.maximum(0.0, 2 * (PUSH_SPEED * steps * TIMESTEP - START_GAP)) / RADIUS
    first = int(steps[ratio > 0.5][0])
    assert (f"check/contact: step {first}: particles 1 and 2 overlap by {ratio[steps == first][0]:.4g} of the "
            "smaller radius, above max_pair_overlap = 0.5") in run.log, run.log[-2000:]


def head_on_collision(pair_every: str) -> str:
    """Two free elastic spheres that meet head-on at 2 x 0.5 m/s; check/contact's full check only at
    set-up (every 10^6), the pair overlap every `pair_every` steps."""
    gap = 2e-6
    return HEADER + f"""create_atoms 1 single -{RADIUS + gap!r} 0 0 units box
create_atoms 1 single  {RADIUS + gap!r} 0 0 units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
velocity all set NULL 0 0 units box
set atom 1 vx 0.5
set atom 2 vx -0.5
fix integr all nve/sphere
timestep {0.1 * RAYLEIGH!r}
fix check all check/contact every 1000000 {pair_every}
thermo_style custom step f_check[1]
thermo_modify format float %.15g norm no
thermo 1000
run 1000
"""


def test_pair_overlap_between_checks_is_seen_with_pair_every(tmp_path):
    # the largest overlap of a head-on Hertz impact (e = 1), closed form: (15 m* v^2 / (16 E* sqrt(R*)))^(2/5)
    # with the relative speed v, m* = m/2, R* = R/2, E* = E / (2 (1 - nu^2)); the contact lasts about
    # 40 steps, between two full checks
    mass = DENSITY * 4 / 3 * math.pi * RADIUS**3
    effective_youngs = YOUNGS / (2 * (1 - POISSON**2))
    peak = (15 * (mass / 2) * 1.0**2 / (16 * effective_youngs * math.sqrt(RADIUS / 2))) ** 0.4
    every_step = run_lmp(head_on_collision("pair_every 1"), tmp_path / "every")
    every_step.assert_clean()
    assert every_step.thermo[-1]["check[1]"][-1] == pytest.approx(peak / RADIUS, rel=2e-3)
    only_checks = run_lmp(head_on_collision(""), tmp_path / "checks")
    only_checks.assert_clean()
    assert only_checks.thermo[-1]["check[1]"][-1] == 0.0    # never seen: the contact fell between checks


def two_overlapping_spheres(dt: float, guard: str, nsteps: int, extra: str = "") -> str:
    """Two spheres released at an overlap of 2 % of the radius each side; elastic (e = 1)."""
    return HEADER + f"""create_atoms 1 single -0.00099 0 0 units box
create_atoms 1 single  0.00099 0 0 units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
{extra}
fix integr all nve/sphere
timestep {dt!r}
fix check all check/contact every 10 {guard}
thermo_style custom step atoms ke f_check[2] f_check[5] f_check[6]
thermo_modify format float %.15g norm no
thermo 10
run {nsteps}
"""


def released_speed() -> float:
    """Speed of each sphere after an elastic release from overlap δ: the Hertz energy
    (2/5) k1 δ^(5/2), k1 = (4/3) E* sqrt(R*), shared equally."""
    effective_youngs = YOUNGS / (2 * (1 - POISSON**2))
    k1 = 4 / 3 * effective_youngs * math.sqrt(RADIUS / 2)
    energy = 0.4 * k1 * (2e-5) ** 2.5
    mass = DENSITY * 4 / 3 * math.pi * RADIUS**3
    return math.sqrt(energy / mass)


def test_safe_time_step_never_trips_the_guards(tmp_path):
    run = run_lmp(two_overlapping_spheres(0.1 * RAYLEIGH, "max_speed 0.5 max_pair_overlap 0.05", 2000), tmp_path)
    run.assert_clean()
    thermo = run.thermo[-1]
    # energy conserved: the spheres leave at the speed the overlap energy gives
    assert thermo["check[5]"][-1] == pytest.approx(released_speed(), rel=2e-3)
    assert f"critical step estimate {RAYLEIGH:.4g} s" in run.log


def test_energy_blow_up_stops_with_the_particle(tmp_path):
    """Ten times the critical step (allowed here with action warn): the first step turns the overlap
    into a speed several times what its energy allows; max_speed stops the run at step 1."""
    run = run_lmp(two_overlapping_spheres(10 * RAYLEIGH, "action warn max_speed 0.5", 100), tmp_path,
                  expect_error=True)
    assert "above the allowed step_fraction 0.2" in run.log          # warned, not stopped
    assert "check/contact: step 1: particle 1 moves at" in run.log, run.log[-2000:]
    assert "above max_speed = 0.5 m/s" in run.log
    assert 0.5 > 2 * released_speed()   # the bound is well above the physical speed


@pytest.mark.parametrize("fraction, events", [(0.9, 2), (1.1, 0)])
def test_fast_particles_are_counted_not_stopped(tmp_path, fraction, events):
    """fast_speed a little below the release speed of the closed form: both spheres are one event
    each, named in the log, and the run goes on; a little above it: none."""
    speed = released_speed()
    guard = f"fast_speed {fraction * speed!r} max_speed {2 * speed!r}"
    run = run_lmp(two_overlapping_spheres(0.1 * RAYLEIGH, guard, 2000), tmp_path)
    run.assert_clean()
    assert run.thermo[-1]["check[6]"][-1] == events          # f_ID[6]: no walls, so the events follow speed
    named = [line for line in run.log.splitlines() if "fast_speed event" in line]
    assert len(named) == min(events, 1)      # both start in the same step: one name per step
    if events:
        assert "fast_speed event 1 (of the first 10 named): step " in named[0]
        assert named[0].split("particle ")[1].split()[0] in {"1", "2"}


@pytest.mark.parametrize("nprocs", [1, 2])
def test_a_fast_particle_crossing_to_another_rank_is_one_event(tmp_path, nprocs):
    """Sphere 2 is released towards +x and crosses x = 0, the boundary between two ranks, while
    above fast_speed: its state goes with it, so the two spheres stay two events."""
    speed = released_speed()
    guard = f"fast_speed {0.9 * speed!r} max_speed {2 * speed!r}"
    text = two_overlapping_spheres(0.1 * RAYLEIGH, guard, 2000).replace(
        "create_atoms 1 single -0.00099 0 0", "create_atoms 1 single -0.00297 0 0").replace(
        "create_atoms 1 single  0.00099 0 0", "create_atoms 1 single -0.00099 0 0").replace(
        "create_box", "processors * 1 1\ncreate_box", 1) + "variable x2 equal x[2]\nprint \"sphere 2 at x = ${x2}\"\n"
    run = run_lmp(text, tmp_path, nprocs=nprocs)
    run.assert_clean()
    assert float(run.log.split("sphere 2 at x = ")[-1].split()[0]) > 0.0005     # it crossed x = 0
    assert run.thermo[-1]["check[6]"][-1] == 2


def test_fast_events_survive_a_restart_file(tmp_path):
    """The count and each particle's state go into the restart file: the two spheres, still above
    fast_speed when read back, are not counted again. (The spheres are apart by then: the continued
    run needs no contact history, which LIGGGHTS' restart of two lone spheres overflows.)"""
    speed = released_speed()
    guard = f"fast_speed {0.9 * speed!r} max_speed {2 * speed!r}"
    text = two_overlapping_spheres(0.1 * RAYLEIGH, guard, 2000) + f"""write_restart two.restart
clear
read_restart two.restart
newton        off
communicate single vel yes
neighbor      0.0005 bin
neigh_modify  delay 0
fix m1 all property/global youngsModulus peratomtype 5.0e7
fix m2 all property/global poissonsRatio peratomtype 0.25
fix m3 all property/global coefficientRestitution peratomtypepair 1 1.0
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential no_history
pair_coeff * *
fix integr all nve/sphere
fix check all check/contact every 10 {guard}
thermo_style custom step atoms ke f_check[2] f_check[5] f_check[6]
thermo_modify format float %.15g norm no
thermo 10
run 100
"""
    run = run_lmp(text, tmp_path)
    run.assert_clean()
    assert run.thermo[-1]["check[5]"][-1] > 0.9 * speed      # still above fast_speed after the restart
    assert run.thermo[-1]["check[6]"][0] == 2 and run.thermo[-1]["check[6]"][-1] == 2


def test_fast_speed_must_be_below_max_speed(tmp_path):
    run = run_lmp(two_overlapping_spheres(0.1 * RAYLEIGH, "fast_speed 2 max_speed 1", 10), tmp_path, expect_error=True)
    assert "fast_speed = 2 m/s must be below max_speed = 1 m/s" in run.log


def test_time_step_above_the_fraction_is_an_error_by_default(tmp_path):
    run = run_lmp(two_overlapping_spheres(0.5 * RAYLEIGH, "", 10), tmp_path, expect_error=True)
    assert (f"check/contact: time step {0.5 * RAYLEIGH:.4g} s is 0.5 of the critical step estimate {RAYLEIGH:.4g} s, "
            f"above the allowed step_fraction 0.2; use timestep <= {0.2 * RAYLEIGH:.4g}") in run.log


def test_non_finite_velocity_stops_with_step_and_particle(tmp_path):
    # after 20 good steps, particle 2 gets the velocity (-1)^0.5 = NaN
    text = two_overlapping_spheres(0.1 * RAYLEIGH, "", 20) + (
        "variable bad equal (-1)^0.5\ngroup two id 2\nvelocity two set v_bad 0 0 units box\nrun 10\n")
    run = run_lmp(text, tmp_path, expect_error=True)
    assert "check/contact: step 20: particle 2 has a non-finite position, velocity or force" in run.log, run.log[-2000:]


@pytest.mark.parametrize("guard", RANK_ONE_GUARDS)
def test_a_guard_on_rank_1_leaves_its_message_in_log_lammps(tmp_path, guard):
    """Issue 37 item 6: a periodic run on 2 ranks, its screen output discarded (a batch job's stdout
    lost with the job), stopped by a guard that only rank 1 sees: the message, naming what and where,
    is in log.lammps. The guards of check/contact and squeeze/ledger reduce their finding across ranks
    and stop every rank with the message of the rank that found it (tsg::fail_from, error->all: rank 0
    writes the log); an error raised by one rank alone (error->one) is appended to the log by that
    rank (patches/error-cpp.patch)."""
    text, files, words = RANK_ONE_GUARDS[guard]
    (tmp_path / "in.guard").write_text(text)
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    proc = subprocess.run(mpi_command(2) + [lmp_executable(), "-in", "in.guard"], cwd=tmp_path,
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=300,
                          env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    assert proc.returncode != 0
    log = (tmp_path / "log.lammps").read_text(errors="replace")
    errors = [line for line in log.splitlines() if line.startswith("ERROR")]
    assert len(errors) == 1, log[-3000:]
    for word in words:
        assert word in errors[0], log[-3000:]
