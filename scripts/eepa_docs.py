"""Regenerate the EEPA figure and the EEPA-vs-stock-`edinburgh` comparison in docs/ by running lmp.

    .venv/bin/python scripts/eepa_docs.py [--lmp build/lmp]

Writes docs/img/eepa_cycle.png (force-overlap of a load-unload-reload cycle computed by lmp) and
docs/eepa-comparison.md (the verification cases of tests/eepa run on both models).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from tsg_cases.eepa_contact import INPUTS, Eepa, closed_form_restitution, cycle_motion, impact, reference_force
from tsg_cases.launcher import LmpFailed, run_lmp

matplotlib.use("Agg")
ROOT = Path(__file__).resolve().parents[1]


STOCK_TIMEOUT = 60  # s; the stock model's unbounded loop can hang


def edinburgh_include(plasticity_ratio: float, restitution: float, pull_off_force: float = 0.0) -> str:
    """The stock model's properties for the same physical case (k2/k1 = 1/(1 - λp), no Δγ)."""
    return "\n".join([
        f"fix m3 all property/global coefficientRestitution peratomtypepair 1 {restitution}",
        f"fix s1 all property/global UnloadingStiffness peratomtypepair 1 {1 / (1 - plasticity_ratio)}",
        "fix s2 all property/global overlapExponent scalar 1.5",
        "fix s3 all property/global adhesionExponent scalar 20",
        f"fix s4 all property/global pullOffForce peratomtypepair 1 {pull_off_force}",
        "fix s5 all property/global surfaceEnergy peratomtypepair 1 0.0",
        "fix s6 all property/global coefficientAdhesionStiffness peratomtypepair 1 0.0",
        "pair_style gran model edinburgh tangential history",
        "pair_coeff * *", ""])


def cycle(workdir: Path, include: str, law: Eepa, timeout: float = 600):
    motion, nsteps = cycle_motion([4e-6, 1.5e-6, 6e-6, 0.4e-6, 1.0e-6, -2e-7], steps_per_leg=400)
    run = run_lmp((INPUTS / "in.quasistatic_cycle").read_text(), workdir, timeout=timeout,
                  variables={"nsteps": nsteps, "dt": 1e-9},
                  files={"model.include": include, "motion.include": motion})
    thermo = run.thermo[-1]
    return thermo["overlap"], thermo["force"], reference_force(thermo["overlap"], law)


def figure(workdir: Path, out: Path) -> None:
    law = Eepa(plasticity_ratio=0.5, pull_off_force=-0.001, surface_energy=15.0, restitution=1.0)
    overlap, force, expected = cycle(workdir, law.include(), law)
    near = overlap > -0.5e-6  # leave out the approach from 100 um away
    overlap, force, expected = overlap[near], force[near], expected[near]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(overlap * 1e6, force * 1e3, lw=1.5, label="lmp, pair_style gran model eepa")
    ax.plot(overlap * 1e6, expected * 1e3, "k:", lw=1, label="law (docs/model.md)")
    ax.axhline(law.pull_off_force * 1e3, color="grey", lw=0.5)
    ax.set_xlabel("overlap δ (μm)")
    ax.set_ylabel("normal force f (mN)")
    ax.set_title("EEPA load–unload–reload cycle (λp 0.5, n 1.5, X 20, f0 −1 mN, Δγ 15 J/m²)", fontsize=8)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=130)


def comparison(workdir: Path) -> str:
    rows = ["| case | expected | `eepa` (ours) | stock `edinburgh` |", "|---|---|---|---|"]

    def both(name: str, expected: float, ours_include: str, stock_include: str, speed: float) -> None:
        ours, _ = impact(workdir / f"{name}-eepa", ours_include, speed)
        try:
            stock, run = impact(workdir / f"{name}-edinburgh", stock_include, speed, timeout=STOCK_TIMEOUT,
                                require_separation=False)
            separated = run.thermo[-1]["gap"][-1] > 0
            stock_text = f"{stock:.5f}" + ("" if separated else " (still touching after 3 contact times)")
        except subprocess.TimeoutExpired:
            stock_text = f"hangs (killed after {STOCK_TIMEOUT} s; ours takes < 1 s)"
        except (LmpFailed, AssertionError) as failure:
            stock_text = "fails: " + str(failure).splitlines()[0][:80]
        rows.append(f"| {name} | {expected:.5f} | {ours:.5f} | {stock_text} |")

    for lam in (0.5, 0.8):
        e = closed_form_restitution(lam, 1.5)
        for speed in (0.1, 1.0):
            both(f"undamped restitution, λp = {lam}, {speed} m/s", e,
                 Eepa(plasticity_ratio=lam, restitution=1.0).include(), edinburgh_include(lam, 1.0), speed)
    for speed in (0.1, 1.0):
        both(f"input e = 0.5, λp = 0, {speed} m/s", 0.5,
             Eepa(plasticity_ratio=0.0, restitution=0.5).include(), edinburgh_include(0.0, 0.5), speed)

    law = Eepa(plasticity_ratio=0.8, pull_off_force=-0.001, restitution=1.0)
    overlap, force, expected = cycle(workdir / "cycle-eepa", law.include(), law)
    ours = np.abs(force - expected).max() / np.abs(expected).max()
    try:
        overlap, force, expected = cycle(workdir / "cycle-edinburgh", edinburgh_include(0.8, 1.0, -0.001), law,
                                         timeout=STOCK_TIMEOUT)
        stock = f"{np.abs(force - expected).max() / np.abs(expected).max():.2e}"
    except subprocess.TimeoutExpired:
        stock = f"hangs (killed after {STOCK_TIMEOUT} s)"
    except LmpFailed as failure:
        stock = "fails: " + str(failure).splitlines()[0][:80]
    rows.append(f"| quasi-static cycle with f0 = −1 mN: max force error / max force | 0 | {ours:.2e} | {stock} |")
    return "\n".join(rows) + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--lmp", default=str(ROOT / "build" / "lmp"))
    args = parser.parse_args()
    os.environ["TSG_LMP"] = str(Path(args.lmp).resolve())
    with tempfile.TemporaryDirectory() as scratch:
        figure(Path(scratch) / "figure", ROOT / "docs" / "img" / "eepa_cycle.png")
        table = comparison(Path(scratch))
    header = ("# EEPA vs the stock LIGGGHTS 3.8.0 `edinburgh` model\n\n"
              "Generated by `scripts/eepa_docs.py` (two spheres, R = 1 mm, E = 50 MPa, ν = 0.25, "
              "2500 kg/m³, n = 1.5, no Δγ; restitution measured from the separation velocities; "
              "dt = 2e-8 s). The stock model gets k2/k1 = 1/(1 − λp) through `UnloadingStiffness`.\n\n")
    (ROOT / "docs" / "eepa-comparison.md").write_text(header + table)
    print(table)
    return 0


if __name__ == "__main__":
    sys.exit(main())
