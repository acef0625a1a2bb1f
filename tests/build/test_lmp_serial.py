"""lmp runs stock Hertz granular inputs; checked against closed forms and conservation laws."""
import math
from pathlib import Path

import numpy as np
import pytest

from tsg_harness import run_lmp

INPUTS = Path(__file__).parent / "inputs"


def hertz_contact_duration(radius, density, youngs, poisson, approach_speed):
    """Hertz (1882) duration of an elastic sphere–sphere impact:
    t_c = 2.868 (m*^2 / (R* E*^2 v))^(1/5), with m* = m/2, R* = R/2, 1/E* = 2(1-nu^2)/E."""
    mass = density * 4.0 / 3.0 * math.pi * radius**3
    m_eff, r_eff = mass / 2, radius / 2
    e_eff = youngs / (2 * (1 - poisson**2))
    return 2.868 * (m_eff**2 / (r_eff * e_eff**2 * approach_speed)) ** 0.2


@pytest.mark.parametrize("speed", [0.2, 1.0])
def test_hertz_impact_conserves_energy_and_matches_contact_duration(tmp_path, speed):
    run = run_lmp((INPUTS / "in.hertz_impact").read_text(), tmp_path, variables={"v": speed, "nsteps": 8000})
    run.assert_clean()
    thermo = run.thermo[-1]
    assert np.all(thermo["Atoms"] == 2)
    ke = thermo["KinEng"]
    mass = 2500 * 4 / 3 * math.pi * 0.001**3
    ke_expected = 2 * 0.5 * mass * speed**2
    assert ke[0] == pytest.approx(ke_expected, rel=1e-9)
    # elastic Hertz contact, no damping: all kinetic energy comes back
    assert ke[-1] == pytest.approx(ke_expected, rel=1e-5)
    gap = thermo["gap"]
    steps = thermo["Step"]
    in_contact = steps[gap < 0]
    assert in_contact.size > 10, "the spheres never touched"
    measured = (in_contact[-1] - in_contact[0] + 10) * 1e-7  # thermo every 10 steps
    expected = hertz_contact_duration(0.001, 2500, 1.0e7, 0.3, 2 * speed)
    assert measured == pytest.approx(expected, rel=0.02)


def test_settling_bed_loses_energy_and_keeps_every_particle(tmp_path):
    run = run_lmp((INPUTS / "in.settle_bed").read_text(), tmp_path, variables={"nsteps": 150000})
    run.assert_clean()
    thermo = run.thermo[-1]
    atoms = thermo["Atoms"]
    assert atoms[0] > 100 and np.all(atoms == atoms[0])
    etot = thermo["etot"]
    drop = etot[0] - etot[-1]
    assert drop > 0
    # dissipative contacts: mechanical energy never grows beyond integration noise
    assert np.max(np.diff(etot)) < 1e-3 * drop
    # the bed has come (nearly) to rest
    assert thermo["KinEng"][-1] < 1e-3 * drop
