"""Two-sphere EEPA contact cases run with lmp (inputs in cases/contact/) and independent reference
values, for the LIGGGHTS-level EEPA tests (tests/eepa) and the figures of scripts/eepa_docs.py.

The reference law here is written from the formulas in docs/model.md (Thakur et al. 2014), not
from the C++ code, so that a test compares two independent computations.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tsg_cases.launcher import LmpRun, run_lmp

INPUTS = Path(__file__).parent / "contact"
RADIUS = 0.001          # m
YOUNGS = 5.0e7          # Pa
POISSON = 0.25
DENSITY = 2500.0        # kg/m^3
MASS = DENSITY * 4.0 / 3.0 * math.pi * RADIUS**3
R_EFF = RADIUS / 2
E_EFF = YOUNGS / (2 * (1 - POISSON**2))
K1 = 4.0 / 3.0 * E_EFF * math.sqrt(R_EFF)   # n = 1.5


@dataclass
class Eepa:
    plasticity_ratio: float = 0.8
    pull_off_force: float = 0.0
    surface_energy: float = 0.0
    slope_exponent: float = 1.5
    tension_exponent: float = 20.0
    tangential_multiplier: float = 0.667
    restitution: float = 0.5

    def include(self, walls: str = "") -> str:
        return "\n".join([
            f"fix m3 all property/global coefficientRestitution peratomtypepair 1 {self.restitution}",
            f"fix e1 all property/global plasticityRatio peratomtypepair 1 {self.plasticity_ratio}",
            f"fix e2 all property/global pullOffForce peratomtypepair 1 {self.pull_off_force}",
            f"fix e3 all property/global surfaceEnergy peratomtypepair 1 {self.surface_energy}",
            f"fix e4 all property/global slopeExponent peratomtypepair 1 {self.slope_exponent}",
            f"fix e5 all property/global tensionExponent peratomtypepair 1 {self.tension_exponent}",
            f"fix e6 all property/global tangentialStiffnessMultiplier peratomtypepair 1 {self.tangential_multiplier}",
            "pair_style gran model eepa tangential history",
            "pair_coeff * *",
            walls, ""])

    def k1(self) -> float:
        return 4.0 / 3.0 * E_EFF * R_EFF ** (2 - self.slope_exponent)


class ReferenceContact:
    """EEPA hysteretic force of one contact, evaluated step by step along its overlap path
    (docs/model.md, Thakur 2014 eqs. for the three branches; pull-off from the plastic overlap at
    the largest overlap). A new contact, and one whose overlap has gone to zero, is virgin."""

    def __init__(self, law: Eepa, effective_radius: float = R_EFF) -> None:
        self.law = law
        self.effective_radius = effective_radius
        self.k1 = law.k1() * (effective_radius / R_EFF) ** (2 - law.slope_exponent)
        self.max_overlap = 0.0
        self.plastic_n = 0.0

    def force(self, overlap: float) -> float:
        law = self.law
        lam, n, x, f0 = law.plasticity_ratio, law.slope_exponent, law.tension_exponent, law.pull_off_force
        k1 = self.k1
        k2 = k1 / (1 - lam)
        if overlap <= 0:
            self.max_overlap, self.plastic_n = 0.0, 0.0      # contact lost: starts virgin
            return 0.0
        overlap_n = overlap**n
        if lam * overlap_n >= self.plastic_n:                 # virgin loading, k1 line
            self.max_overlap = max(self.max_overlap, overlap)
            self.plastic_n = lam * overlap_n
            return f0 + k1 * overlap_n
        plastic_max_n = lam * self.max_overlap**n             # δp of the virgin unloading line
        pull = 0.0
        if law.surface_energy > 0:
            contact_radius = math.sqrt(2 * self.effective_radius * plastic_max_n ** (1 / n))
            f_min = min(1.5 * math.pi * law.surface_energy * contact_radius, 0.5 * k2 * plastic_max_n)
            overlap_min = (plastic_max_n - f_min / k2) ** (1 / n)
            pull = f_min if overlap >= overlap_min else f_min * (overlap / overlap_min) ** x
        line = k2 * (overlap_n - self.plastic_n)
        if line >= -pull:                                     # unloading / reloading, k2 line
            return f0 + line
        self.plastic_n = overlap_n + pull / k2                # adhesive branch
        return f0 - pull


def reference_force(overlaps: np.ndarray, law: Eepa) -> np.ndarray:
    """EEPA hysteretic force along an overlap path (ReferenceContact)."""
    contact = ReferenceContact(law)
    return np.array([contact.force(float(overlap)) for overlap in overlaps])


def closed_form_restitution(plasticity_ratio: float, slope_exponent: float) -> float:
    """Undamped, non-adhesive: e^2 = work returned on k2 / work done on k1
    = [1 - (n+1) λ + n λ^(1+1/n)] / (1 - λ)  (derived in docs/model.md, "Restitution")."""
    lam, n = plasticity_ratio, slope_exponent
    return math.sqrt((1 - (n + 1) * lam + n * lam ** (1 + 1 / n)) / (1 - lam))


def impact(tmp_path: Path, model_include: str, speed: float, dt: float = 2e-8,
           nprocs: int = 1, timeout: float = 600, require_separation: bool = True) -> tuple[float, LmpRun]:
    """Head-on impact of two spheres at ±speed; returns the measured restitution (from the final
    velocities; with require_separation=False also when the spheres are still touching)."""
    approach = 2 * speed
    max_overlap = (5 * (MASS / 2) * approach**2 / (4 * K1)) ** 0.4    # Hertz energy balance
    contact_time = 2.943 * max_overlap / approach                      # Johnson (1985) eq. 11.24
    gap = 4e-6                                                         # initial gap in the input
    nsteps = int((gap / approach + 3 * contact_time) / dt) // 100 * 100 + 100
    run = run_lmp((INPUTS / "in.two_sphere_impact").read_text(), tmp_path, nprocs=nprocs, timeout=timeout,
                  variables={"v": speed, "nsteps": nsteps, "dt": dt},
                  files={"model.include": model_include})
    thermo = run.thermo[-1]
    if require_separation:
        assert thermo["gap"][-1] > 0, "spheres still in contact at the end of the run"
    restitution = (thermo["v2"][-1] - thermo["v1"][-1]) / (2 * speed)
    return restitution, run


def cycle_motion(turning_overlaps: list[float], steps_per_leg: int, start_overlap: float = -1e-7) -> tuple[str, int]:
    """`fix move variable` displacement for a piecewise-linear overlap path through the turning
    points (atom 2 starts 0.1 mm from touching); returns the include text and the step count."""
    points = [start_overlap] + turning_overlaps
    slopes = [(b - a) / steps_per_leg for a, b in zip(points[:-1], points[1:])]
    terms = [f"{start_overlap!r}"]
    previous = 0.0
    for leg, slope in enumerate(slopes):
        change = slope - previous
        terms.append(f"({change!r})*(step-{leg * steps_per_leg})*(step>{leg * steps_per_leg})")
        previous = slope
    overlap = "+".join(terms)
    text = (f"variable delta equal {overlap}\n"
            f"variable xdrive equal -1.0e-4-v_delta\n"
            f"variable vdrive equal 0.0\n")
    return text, steps_per_leg * len(slopes)
