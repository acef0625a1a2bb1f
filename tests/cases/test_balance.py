"""fix balance/x (issue 17 item 2): the x cuts between ranks move to equal particle counts.

Checked against what LIGGGHTS itself does with the cuts: the particles each rank owns are counted
from a dump and the cuts in the thermo output, independently of the fix; forces, particles and
contact histories of a run whose cuts move are those of a serial run (particles on prescribed paths
among the screws, as in test_corotating.py, so that per-step forces can be compared exactly).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from test_corotating import (ABSOLUTE_SHARE, INPUTS, PERIODIC_LENGTH, RELATIVE, atoms_in_bores, compare,  # noqa: F401
                             periodic_meshes, read_dump)
from tsg_harness import run_lmp

# ---- cuts follow a moving fill ------------------------------------------------------------------

BOX_LENGTH = 0.1
FILL = (0.005, 0.025)     # m, the block the particles start in
SPEED = 1.0               # m/s along +x
DT = 1e-5
EVERY = 100               # balancing interval = thermo = dump interval, steps
NSTEPS = 5000
RANKS = 4
BIN = BOX_LENGTH / (100 * RANKS)  # the fix's histogram bin (kBinsPerRank = 100)

FILL_INPUT = f"""atom_style    granular
atom_modify   map array
boundary      ${{xbound}} f f
newton        off
communicate   single vel yes
units         si
processors    * 1 1
region        box block 0 {BOX_LENGTH} 0 0.01 0 0.01 units box
create_box    1 box
neighbor      0.0005 bin
neigh_modify  delay 0
fix m1 all property/global youngsModulus peratomtype 5.0e7
fix m2 all property/global poissonsRatio peratomtype 0.25
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
include atoms.in
set atom * diameter 0.0002 density 2500
fix push all move linear {SPEED} 0 0
timestep {DT}
fix bal all balance/x {EVERY}
thermo_style custom step atoms f_bal {" ".join(f"f_bal[{k}]" for k in range(1, RANKS + 2))}
thermo_modify format float %.15g
thermo {EVERY}
dump d all custom {EVERY} fill.dump id x
dump_modify d sort id format "%d %.17g"
run {NSTEPS}
"""


def fill_atoms(count: int, seed: int) -> tuple[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    x = rng.uniform(*FILL, count)
    yz = rng.uniform(0.001, 0.009, (count, 2))
    lines = "".join(f"create_atoms 1 single {a:.12e} {b:.12e} {c:.12e} units box\n" for a, (b, c) in zip(x, yz))
    return lines, x


@pytest.mark.parametrize("xbound", ["f", "p"])
def test_cuts_follow_a_moving_fill(tmp_path, xbound):
    atoms, _ = fill_atoms(2000, 11)
    run = run_lmp(FILL_INPUT, tmp_path, nprocs=RANKS, variables={"xbound": xbound}, files={"atoms.in": atoms})
    run.assert_clean()
    thermo = run.thermo[-1]
    frames = {step: rows for step, rows in read_dump(tmp_path / "fill.dump")}
    assert np.all(thermo["Atoms"] == 2000)
    converged = 0
    for n, step in enumerate(thermo["Step"].astype(int)):
        x = frames[step][:, 1]
        assert len(x) == 2000
        cuts = np.array([thermo[f"bal[{k}]"][n] for k in range(1, RANKS + 2)])
        assert cuts[0] == 0.0 and cuts[-1] == BOX_LENGTH
        # the ranks' particle counts, from the dumped positions and the printed cuts: the cuts moved
        # on this step and LIGGGHTS re-distributed the particles, so the fix's own imbalance (from
        # each rank's particle count) must be exactly this one
        counts = np.histogram(x, bins=cuts)[0]
        assert counts.sum() == 2000
        assert thermo["bal"][n] == pytest.approx(counts.max() * RANKS / 2000, rel=1e-12), (step, counts)
        if step >= 3 * EVERY:  # three moves in: each cut at its quantile of the fill, within a bin
            quantiles = np.quantile(x, np.arange(1, RANKS) / RANKS)
            assert np.all(np.abs(cuts[1:-1] - quantiles) <= 2 * BIN), (step, cuts, quantiles)
            # a cut within its bin: a rank is off its share by at most the two end bins' particles
            per_bin = np.histogram(x, bins=np.arange(0.0, BOX_LENGTH + BIN / 2, BIN))[0].max()
            assert counts.max() <= 2000 / RANKS + 2 * per_bin, (step, counts, per_bin)
            converged += 1
    # the fill moved SPEED * t and the middle cut with it
    moved = thermo["bal[3]"][-1] - thermo["bal[3]"][3]
    assert moved == pytest.approx(SPEED * DT * (NSTEPS - 3 * EVERY), abs=2 * BIN)
    assert converged == NSTEPS // EVERY - 2
    # equal slabs (what LIGGGHTS does without the fix) would put the whole fill on rank 0 at first
    _, x0 = fill_atoms(2000, 11)
    assert np.histogram(x0, bins=np.linspace(0, BOX_LENGTH, RANKS + 1))[0].max() == 2000


# ---- same particles, same forces, same contact histories -----------------------------------------

def run_screw_paths(workdir: Path, mesh_dir: Path, atoms: str, *, drive: str, nprocs: int, balance_every: int,
                    nsteps: int = 300, restart_every: int = 0, restart_from: Path | None = None, extra: str = ""):
    """tests/cases/inputs/in.corotating_paths with a `processors * 1 1` grid, if balance_every > 0 fix
    balance/x, and the commands `extra` after the walls; returns (run, dump frames)."""
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / "atoms.in").write_text(atoms)
    start = INPUTS / ("start_restart.in" if restart_from else "start_fresh.in")
    (workdir / "start.in").write_text("processors * 1 1\n" + start.read_text())
    drive_text = (INPUTS / f"drive_{drive}.in").read_text() + "\n" + extra
    if balance_every > 0:
        drive_text += f"\nfix bal all balance/x {balance_every}\n"
        drive_text += "thermo_style custom step atoms f_bal " + " ".join(f"f_bal[{k}]" for k in range(1, nprocs + 2))
        drive_text += "\nthermo_modify format float %.15g\n"
    (workdir / "drive.in").write_text(drive_text)
    variables = {
        "start_file": workdir / "start.in", "restart_file": restart_from if restart_from else workdir / "restart",
        "mesh_dir": mesh_dir, "drive_file": workdir / "drive.in", "atoms_file": workdir / "atoms.in",
        "xlo": 0.0, "xhi": PERIODIC_LENGTH, "xbound": "p", "vx": 3.0, "vy": 1.0, "vz": -0.01, "dt": 2e-6,
        "period": 0.1, "nsteps": nsteps, "restart_every": restart_every, "out": workdir / "forces.dump",
        "dump_every": 1,
    }
    run = run_lmp((INPUTS / "in.corotating_paths").read_text(), workdir, nprocs=nprocs, variables=variables,
                  timeout=900)
    run.assert_clean()
    return run, read_dump(workdir / "forces.dump")


def crowded_atoms(seed: int) -> str:
    """800 particles in the first third of the periodic screws: equal slabs are far from balanced."""
    return atoms_in_bores(np.random.default_rng(seed), 800, [(0.0, PERIODIC_LENGTH / 3)])


@pytest.mark.parametrize("drive", ["corotating", "stock"])
def test_moving_cuts_change_no_force(tmp_path, periodic_meshes, drive):
    """Four ranks whose cuts move every 25 steps give the forces and torques of one rank, step by step,
    for the same particles: contacts with the screws (turned by fix wall/gran/corotating or by fix
    move/mesh) and the static barrel, whose triangles LIGGGHTS re-distributes as the cuts move.

    Corotating: equal to the last bit's rounding. Stock: the stock path's forces depend on the steps
    on which it re-neighbours and on LIGGGHTS treating the sub-domains as changing (what the fix asks
    for), not on the cuts: measured, a 1-rank run with the fix forced to act as on 4 ranks (no cut to
    move) differs from the plain 1-rank run by the same 1.738e-10 relative as the 4-rank balanced run
    does (docs/performance.md); the bound is the one test_corotating.py allows the stock path."""
    atoms = crowded_atoms(13)
    _, serial = run_screw_paths(tmp_path / "np1", periodic_meshes, atoms, drive=drive, nprocs=1, balance_every=0)
    run, balanced = run_screw_paths(tmp_path / "np4", periodic_meshes, atoms, drive=drive, nprocs=4,
                                    balance_every=25)
    thermo = run.thermo[-1]
    assert np.all(thermo["Atoms"] == 800)
    cuts = np.array([thermo[f"bal[{k}]"] for k in range(2, 5)])
    # the cuts did move, away from equal slabs, and more than once
    assert np.abs(cuts[:, -1] - PERIODIC_LENGTH * np.arange(1, 4) / 4).max() > PERIODIC_LENGTH / 8
    assert len({tuple(c) for c in cuts.T}) >= 3
    assert thermo["bal"][-1] < 1.2
    result = compare(serial, balanced, first_step=0)
    print(f"{drive}: {result}; cuts at the end {cuts[:, -1]}; imbalance {thermo['bal'][0]} -> {thermo['bal'][-1]}")
    assert result["contacts"] > 1000
    relative, absolute = (1e-12, 1e-14) if drive == "corotating" else (RELATIVE, ABSOLUTE_SHARE)
    assert result["relative"] <= relative and result["absolute"] <= absolute, result
