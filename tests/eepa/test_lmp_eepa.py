"""EEPA in LIGGGHTS: impacts, the quasi-static cycle, walls, cohesive clusters, MPI, bad input."""
import math

import numpy as np
import pytest

from tsg_harness import run_lmp

from tsg_cases.eepa_contact import (INPUTS, K1, Eepa, closed_form_restitution, cycle_motion, impact,
                                    reference_force)


@pytest.mark.parametrize("plasticity_ratio", [0.2, 0.5, 0.8])
@pytest.mark.parametrize("speed", [0.1, 1.0])
def test_undamped_impact_restitution_matches_closed_form(tmp_path, plasticity_ratio, speed):
    law = Eepa(plasticity_ratio=plasticity_ratio, restitution=1.0)
    measured, run = impact(tmp_path, law.include(), speed)
    run.assert_clean()
    assert measured == pytest.approx(closed_form_restitution(plasticity_ratio, 1.5), abs=2e-4)


@pytest.mark.parametrize("restitution", [0.5, 0.9])
@pytest.mark.parametrize("speed", [0.1, 1.0])
def test_damping_recovers_input_restitution_without_plasticity(tmp_path, restitution, speed):
    law = Eepa(plasticity_ratio=0.0, restitution=restitution)
    measured, run = impact(tmp_path, law.include(), speed)
    run.assert_clean()
    # Hertz-Mindlin dashpot (Tsuji 1992) on the Hertz branch: within 1% of the input, any speed
    assert measured == pytest.approx(restitution, rel=0.01)


def test_damped_plastic_restitution_is_speed_independent(tmp_path):
    law = Eepa(plasticity_ratio=0.5, restitution=0.5)
    slow, _ = impact(tmp_path / "slow", law.include(), 0.1)
    fast, _ = impact(tmp_path / "fast", law.include(), 1.0)
    assert 0 < slow < closed_form_restitution(0.5, 1.5)
    assert fast == pytest.approx(slow, rel=1e-3)


@pytest.mark.parametrize("law", [
    Eepa(plasticity_ratio=0.8, pull_off_force=-0.001, restitution=1.0),
    Eepa(plasticity_ratio=0.5, pull_off_force=-0.001, surface_energy=15.0, restitution=1.0),
    Eepa(plasticity_ratio=0.8, pull_off_force=0.0, surface_energy=15.0, tension_exponent=5, restitution=1.0),
], ids=["f0-only", "f0+surface-energy", "surface-energy-X5"])
def test_quasistatic_cycle_force_follows_the_law(tmp_path, law):
    # load to 4 um, unload to 1.5 um, reload past the old maximum to 6 um, unload through the
    # adhesive branch, reload a little, then separate
    turning = [4e-6, 1.5e-6, 6e-6, 0.4e-6, 1.0e-6, -2e-7]
    motion, nsteps = cycle_motion(turning, steps_per_leg=400)
    run = run_lmp((INPUTS / "in.quasistatic_cycle").read_text(), tmp_path,
                  variables={"nsteps": nsteps, "dt": 1e-9},
                  files={"model.include": law.include(), "motion.include": motion})
    run.assert_clean()
    thermo = run.thermo[-1]
    overlap, force = thermo["overlap"], thermo["force"]
    assert overlap.max() == pytest.approx(6e-6, rel=1e-3)
    expected = reference_force(overlap, law)
    scale = np.abs(expected).max()
    np.testing.assert_allclose(force, expected, rtol=0, atol=1e-6 * scale)
    # the cycle visited every branch: loading (k1), unloading (k2) and, with Δγ, adhesion below f0
    assert np.any(np.isclose(force, law.pull_off_force + law.k1() * np.clip(overlap, 0, None)**1.5, rtol=1e-9) & (overlap > 1e-6))
    if law.surface_energy > 0:
        assert force.min() < law.pull_off_force - 1e-6 * scale


def test_particle_wall_impact_with_hertz_walls_in_the_same_run(tmp_path):
    # the paper's set-up: EEPA between particles, Hertz-Mindlin with CDT rolling for the geometry
    walls = ("fix m7 all property/global coefficientRollingFriction peratomtypepair 1 0.01\n"
             "fix floor all wall/gran model hertz tangential history rolling_friction cdt primitive type 1 xplane -0.002003\n")
    text = (INPUTS / "in.two_sphere_impact").read_text()
    # one sphere only, flying at the wall
    text = text.replace("create_atoms 1 single  0.001002 0 0 units box\n", "")
    text = text.replace("set atom 2 vx -${v}\n", "").replace("set atom 1 vx  ${v}", "set atom 1 vx -${v}")
    text = text.replace("variable gap equal x[2]-x[1]-0.002", "variable gap equal x[1]-0.001+0.002003")
    text = text.replace("variable v2 equal vx[2]", "variable v2 equal 0")
    law = Eepa(plasticity_ratio=0.8, restitution=0.7)
    run = run_lmp(text, tmp_path, variables={"v": 0.5, "nsteps": 20000, "dt": 5e-8},
                  files={"model.include": law.include(walls)})
    run.assert_clean()
    thermo = run.thermo[-1]
    assert thermo["gap"][-1] > 0 and thermo["v1"][-1] > 0, "the sphere did not rebound"
    assert thermo["v1"][-1] / 0.5 == pytest.approx(0.7, rel=0.01)   # Hertz wall keeps its e


def test_eepa_on_walls_is_defined_and_matches_the_closed_form(tmp_path):
    # EEPA selected for the wall too: same law with R* = R; the undamped restitution of a sphere
    # on a rigid wall has the same closed form as the two-body impact (it depends on λp and n only)
    walls = "fix floor all wall/gran model eepa tangential history primitive type 1 xplane -0.002003\n"
    text = (INPUTS / "in.two_sphere_impact").read_text()
    text = text.replace("create_atoms 1 single  0.001002 0 0 units box\n", "")
    text = text.replace("set atom 2 vx -${v}\n", "").replace("set atom 1 vx  ${v}", "set atom 1 vx -${v}")
    text = text.replace("variable gap equal x[2]-x[1]-0.002", "variable gap equal x[1]-0.001+0.002003")
    text = text.replace("variable v2 equal vx[2]", "variable v2 equal 0")
    law = Eepa(plasticity_ratio=0.5, pull_off_force=0.0, restitution=1.0)
    run = run_lmp(text, tmp_path, variables={"v": 0.5, "nsteps": 20000, "dt": 2e-8},
                  files={"model.include": law.include(walls)})
    run.assert_clean()
    thermo = run.thermo[-1]
    assert all(np.all(np.isfinite(c)) for c in thermo.values())
    assert thermo["gap"][-1] > 0, "the sphere did not leave the wall"
    assert thermo["v1"][-1] / 0.5 == pytest.approx(closed_form_restitution(0.5, 1.5), abs=2e-4)


def cluster_input(law: Eepa, nsteps: int) -> tuple[str, dict]:
    text = (INPUTS / "in.two_sphere_impact").read_text()
    start = text.index("create_atoms 1 single -0.001002")
    end = text.index("fix integr")
    cluster = """lattice sc 0.00205
region cube block -2 2 -2 2 -2 2 units lattice
create_atoms 1 region cube
set group all diameter 0.002 density 2500
# converge on the centre (about 0.1 m/s at the corners) with a deterministic stir on top
variable vx atom -20*x+0.02*sin(3000*y+1)
variable vy atom -20*y+0.02*cos(2000*z)
variable vz atom -20*z+0.02*sin(2500*x+2)
velocity all set v_vx v_vy v_vz units box
fix check all check/contact every 100 step_fraction 0.2
"""
    text = text[:start] + cluster + text[end:]
    text = text.replace("variable gap equal x[2]-x[1]-0.002\nvariable v1 equal vx[1]\nvariable v2 equal vx[2]\n",
                        "compute vmax all reduce max vx vy vz\nvariable speed equal sqrt(c_vmax[1]^2+c_vmax[2]^2+c_vmax[3]^2)\n")
    text = text.replace("thermo_style custom step atoms ke v_gap v_v1 v_v2",
                        "thermo_style custom step atoms ke v_speed f_check[1] f_check[4]")
    text = text.replace("region        box block -0.01 0.01", "region        box block -0.02 0.02")
    text = text.replace("-0.01 0.01 -0.01 0.01 units box", "-0.02 0.02 -0.02 0.02 units box")
    return text, {"model.include": law.include()}


COHESIVE = Eepa(plasticity_ratio=0.8, pull_off_force=-0.001, surface_energy=15.0, restitution=0.5)


def test_cohesive_cluster_forms_and_stays_bounded(tmp_path):
    text, files = cluster_input(COHESIVE, 60000)
    run = run_lmp(text, tmp_path, variables={"v": 0, "nsteps": 60000, "dt": 1e-7}, files=files)
    run.assert_clean()
    thermo = run.thermo[-1]
    assert np.all(thermo["Atoms"] == 125)   # 5 x 5 x 5 lattice sites
    for column in thermo.values():
        assert np.all(np.isfinite(column))
    # nobody is ejected at absurd speed: never faster than the initial stir plus what the
    # adhesive wells can give (f0·δ scale), far below 1 m/s
    assert thermo["speed"].max() < 0.5
    # the cluster dissipates: kinetic energy ends well below where it started
    assert thermo["KinEng"][-1] < 0.5 * thermo["KinEng"][0]
    assert thermo["check[1]"].max() < 0.05, "overlaps beyond 5% of the radius"


def test_cohesive_cluster_same_on_one_and_two_ranks(tmp_path):
    text, files = cluster_input(COHESIVE, 2000)
    serial = run_lmp(text, tmp_path / "np1", variables={"v": 0, "nsteps": 2000, "dt": 1e-7}, files=files)
    parallel = run_lmp(text, tmp_path / "np2", nprocs=2, variables={"v": 0, "nsteps": 2000, "dt": 1e-7}, files=files)
    s, p = serial.thermo[-1], parallel.thermo[-1]
    assert s["Step"].size == 21
    for column in ("Atoms", "KinEng", "speed", "check[1]"):
        np.testing.assert_allclose(p[column], s[column], rtol=1e-10, atol=0, err_msg=column)


@pytest.mark.parametrize("name,value,allowed", [
    ("plasticityRatio", 1.0, "[0, 1)"),
    ("plasticityRatio", -0.1, "[0, 1)"),
    ("slopeExponent", 0.9, "[1, inf)"),
    ("tensionExponent", 0.5, "[1, inf)"),
    ("surfaceEnergy", -1.0, "[0, inf)"),
    ("pullOffForce", 0.001, "(-inf, 0]"),
    ("tangentialStiffnessMultiplier", 0.0, "(0, inf)"),
])
def test_out_of_range_property_is_a_clear_error(tmp_path, name, value, allowed):
    include = Eepa().include()
    include = "\n".join(
        f"fix {l.split()[1]} all property/global {name} peratomtypepair 1 {value}" if f" {name} " in l else l
        for l in include.splitlines())
    run = run_lmp((INPUTS / "in.two_sphere_impact").read_text(), tmp_path,
                  variables={"v": 0.1, "nsteps": 10, "dt": 1e-8}, files={"model.include": include},
                  expect_error=True)
    message = " ".join(run.errors)
    assert name in message and allowed in message, message


def test_missing_property_is_a_clear_error(tmp_path):
    include = "\n".join(l for l in Eepa().include().splitlines() if "tensionExponent" not in l)
    run = run_lmp((INPUTS / "in.two_sphere_impact").read_text(), tmp_path,
                  variables={"v": 0.1, "nsteps": 10, "dt": 1e-8}, files={"model.include": include},
                  expect_error=True)
    assert "tensionExponent" in " ".join(run.errors), run.errors


def rayleigh_step(youngs: float, plasticity_ratio: float) -> float:
    """Rayleigh time of the 1 mm spheres times sqrt(1 - λp) (Li, Xu & Thornton 2005)."""
    shear = youngs / (2 * (1 + 0.25))
    rayleigh = math.pi * 0.001 * math.sqrt(2500 / shear) / (0.1631 * 0.25 + 0.8766)
    return rayleigh * math.sqrt(1 - plasticity_ratio)


EXTREME_CASES = {
    "stiff": (dict(plasticity_ratio=0.8, pull_off_force=-0.001, surface_energy=15.0, restitution=0.5), 5.0e9),
    "cohesive-x10": (dict(plasticity_ratio=0.8, pull_off_force=-0.01, surface_energy=150.0, restitution=0.5), 5.0e7),
    "elastic": (dict(plasticity_ratio=0.0, restitution=0.9), 5.0e7),
}


def stiffen(text: str, youngs: float) -> str:
    text = text.replace("youngsModulus peratomtype 5.0e7", f"youngsModulus peratomtype {youngs}")
    return text.replace("units         si", "units         si\nhard_particles yes") if youngs > 1e9 else text


@pytest.mark.parametrize("case", EXTREME_CASES)
def test_extreme_case_is_stable_at_the_suggested_step(tmp_path, case):
    params, youngs = EXTREME_CASES[case]
    law = Eepa(**params)
    dt = 0.2 * rayleigh_step(youngs, law.plasticity_ratio)
    nsteps = int(5e-3 / dt)
    text, files = cluster_input(law, nsteps)
    text = stiffen(text, youngs)
    run = run_lmp(text, tmp_path, variables={"v": 0, "nsteps": nsteps, "dt": dt}, files=files)
    run.assert_clean()
    # the fix's estimate is the independent formula above
    assert f"critical step estimate {rayleigh_step(youngs, law.plasticity_ratio):.4g} s" in run.log
    thermo = run.thermo[-1]
    assert np.all(thermo["Atoms"] == 125)
    assert all(np.all(np.isfinite(c)) for c in thermo.values())
    assert thermo["speed"].max() < 0.5
    assert thermo["check[1]"].max() < 0.05


@pytest.mark.parametrize("case", EXTREME_CASES)
def test_extreme_case_above_the_allowed_step_stops_with_a_clear_error(tmp_path, case):
    params, youngs = EXTREME_CASES[case]
    law = Eepa(**params)
    dt = 2.0 * rayleigh_step(youngs, law.plasticity_ratio)
    text, files = cluster_input(law, 100)
    text = stiffen(text, youngs)
    text = text.replace("step_fraction 0.2", "step_fraction 0.2 action error")
    run = run_lmp(text, tmp_path, variables={"v": 0, "nsteps": 100, "dt": dt}, files=files, expect_error=True)
    message = " ".join(run.errors)
    assert "check/contact: time step" in message and "allowed step_fraction 0.2" in message, message
