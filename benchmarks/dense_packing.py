"""Step time of a dense cohesive packing with EEPA vs Hertz vs the stock `edinburgh` model,
measured side by side in one invocation (same machine state, same particles, same steps).

    .venv/bin/python benchmarks/dense_packing.py [--lmp build/lmp] [--side 16] [--steps 2000] [--repeat 3]

Prints ms/step per model (best of --repeat) and the ratios to Hertz. Not a test: numbers depend on
the machine; the README and docs quote what it printed.
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from tsg_cases.launcher import run_lmp

ROOT = Path(__file__).resolve().parents[1]

TEMPLATE = """
atom_style granular
atom_modify map array
boundary p p p
newton off
communicate single vel yes
units si
region box block 0 {box} 0 {box} 0 {box} units box
create_box 1 box
neighbor 0.0002 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 1.3e7
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
{properties}
pair_style gran model {model} tangential history
pair_coeff * *
# periodic simple cubic lattice with 1% overlap: every particle keeps six equal contacts, the
# forces balance, and every model evaluates the same contacts every step
lattice sc 0.00099
create_atoms 1 box
set group all diameter 0.001 density 1263
fix integr all nve/sphere
timestep 5e-7
compute contacts all contact/atom
compute nc all reduce ave c_contacts
thermo_style custom step atoms c_nc
thermo {steps}
run 200
run {steps}
"""

EEPA = """fix e1 all property/global plasticityRatio peratomtypepair 1 0.8
fix e2 all property/global pullOffForce peratomtypepair 1 -0.001
fix e3 all property/global surfaceEnergy peratomtypepair 1 15.0
fix e4 all property/global slopeExponent peratomtypepair 1 1.5
fix e5 all property/global tensionExponent peratomtypepair 1 20
fix e6 all property/global tangentialStiffnessMultiplier peratomtypepair 1 0.667"""
EDINBURGH = """fix s1 all property/global UnloadingStiffness peratomtypepair 1 5.0
fix s2 all property/global overlapExponent scalar 1.5
fix s3 all property/global adhesionExponent scalar 20
fix s4 all property/global pullOffForce peratomtypepair 1 -0.001
fix s5 all property/global surfaceEnergy peratomtypepair 1 15.0
fix s6 all property/global coefficientAdhesionStiffness peratomtypepair 1 0.0"""
MODELS = {"hertz": "", "eepa": EEPA, "edinburgh": EDINBURGH}
LOOP = re.compile(r"Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps with (\d+) atoms")


def step_time(workdir: Path, model: str, side: int, steps: int) -> tuple[float, int]:
    spacing = 0.00099
    text = TEMPLATE.format(box=side * spacing, steps=steps, model=model, properties=MODELS[model])
    run = run_lmp(text, workdir, timeout=900)
    seconds, nsteps, atoms = LOOP.findall(run.log)[-1]
    contacts = run.thermo[-1]["nc"]  # mean contacts per particle
    assert contacts.min() == contacts.max() == 6, f"{model}: the packing changed ({contacts})"
    return float(seconds) / int(nsteps) * 1e3, int(atoms)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--lmp", default=str(ROOT / "build" / "lmp"))
    parser.add_argument("--side", type=int, default=16, help="particles per lattice edge")
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    os.environ["TSG_LMP"] = str(Path(args.lmp).resolve())
    best: dict[str, float] = {}
    atoms = 0
    with tempfile.TemporaryDirectory() as scratch:
        for attempt in range(args.repeat):       # interleaved, so drifts in machine load hit all alike
            for model in MODELS:
                try:
                    ms, atoms = step_time(Path(scratch) / f"{model}-{attempt}", model, args.side, args.steps)
                except subprocess.TimeoutExpired:
                    ms = float("inf")
                best[model] = min(best.get(model, float("inf")), ms)
    print(f"dense packing, {atoms} particles with 6 contacts each, {args.steps} steps, best of {args.repeat}")
    print(f"{'model':<12}{'ms/step':>10}{'vs hertz':>10}{'M particle-steps/s':>20}")
    for model, ms in best.items():
        print(f"{model:<12}{ms:>10.3f}{ms / best['hertz']:>10.2f}{atoms / ms / 1e3:>20.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
