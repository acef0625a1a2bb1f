"""fix wall/gran/corotating (issue 8): screws turned without moving their meshes.

Every comparison is against the stock path (fix move/mesh rotate + fix wall/gran) or against the
corotating path itself under a different decomposition or a restart. Particles follow prescribed
straight paths (fix move), so per-step forces can be compared without chaotic divergence.

Agreement with the stock path is limited by the stock path itself: fix move/mesh turns the mesh by
adding ω dt every step, so its node coordinates accumulate round-off (~n ε |r| after n steps)
while the corotating fix computes the angle from time. Over the first 150 steps the difference
stays below 1e-9 relative for every contact that carries more than 1e-3 of the step's largest
force; for the smaller, incipient contacts (overlaps of nanometres) the bound is 1e-12 of the
step's largest force in absolute terms. The setup step (step 0) is not compared: there the stock
mesh has zero velocity (fix move/mesh sets it in the first step), the corotating screw its true
surface velocity.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tsg_harness import run_lmp
from tsg_meshes.machine import CENTRE_DISTANCE

INPUTS = Path(__file__).parent / "inputs"
SOURCE = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).parents[2]))
HALF_CENTRE = CENTRE_DISTANCE / 2
BORE = 0.0125
PERIODIC_LENGTH = 0.0958333333333333  # consigma1-periodic: C7/6 K6x60R C7/6
RELATIVE = 1e-9
SMALL_SHARE = 1e-3
ABSOLUTE_SHARE = 1e-12


# ---- inputs -------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def element_meshes(tmp_path_factory) -> Path:
    """Conveying, kneading and chopping elements (tests/cases/inputs/corotating-elements.spec)."""
    out = tmp_path_factory.mktemp("elements")
    subprocess.run([sys.executable, "-m", "tsg_meshes", "build", str(INPUTS / "corotating-elements.spec"),
                    str(out), "--tolerance", "20e-6"], check=True, cwd=SOURCE / "meshes",
                   capture_output=True, text=True)
    return out


@pytest.fixture(scope="module")
def periodic_meshes(tmp_path_factory) -> Path:
    """The periodic ConsiGma-1 screws at 20 um (12 860 triangles each), built for this test."""
    out = tmp_path_factory.mktemp("periodic")
    subprocess.run([sys.executable, "-m", "tsg_meshes", "build", "consigma1-periodic", str(out),
                    "--tolerance", "20e-6"], check=True, cwd=SOURCE / "meshes", capture_output=True, text=True)
    return out


def atoms_in_bores(rng: np.random.Generator, count: int, x_ranges: list[tuple[float, float]]) -> str:
    """create_atoms lines: centres in either bore, at least 0.4 mm inside the barrel (0.5 mm particles:
    some overlap the barrel)."""
    lines = []
    while len(lines) < count:
        lo, hi = x_ranges[len(lines) % len(x_ranges)]
        x = rng.uniform(lo, hi)
        y = rng.uniform(-HALF_CENTRE - BORE, HALF_CENTRE + BORE)
        z = rng.uniform(-BORE, BORE)
        if min(np.hypot(y + HALF_CENTRE, z), np.hypot(y - HALF_CENTRE, z)) < BORE - 0.0004:
            lines.append(f"create_atoms 1 single {x:.12e} {y:.12e} {z:.12e} units box\n")
    return "".join(lines)


def run_paths(workdir: Path, drive: str, mesh_dir: Path, atoms: str, *, periodic: bool, nsteps: int,
              nprocs: int = 1, period: float = 0.1, restart_every: int = 0, restart_from: Path | None = None,
              extra_drive: str = "", expect_error: bool = False, velocity=(0.01, 0.02, -0.01)):
    """Run tests/cases/inputs/in.corotating_paths; returns (run, dump frames)."""
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / "atoms.in").write_text(atoms)
    drive_file = INPUTS / f"drive_{drive}.in"
    if extra_drive:
        drive_file = workdir / "drive.in"
        drive_file.write_text(extra_drive)
    variables = {
        "start_file": INPUTS / ("start_restart.in" if restart_from else "start_fresh.in"),
        "restart_file": restart_from if restart_from else workdir / "restart",
        "mesh_dir": mesh_dir, "drive_file": drive_file, "atoms_file": workdir / "atoms.in",
        "xlo": 0.0 if periodic else -0.001, "xhi": PERIODIC_LENGTH if periodic else 0.047,
        "xbound": "p" if periodic else "f", "vx": velocity[0], "vy": velocity[1], "vz": velocity[2], "dt": 2e-6,
        "period": period, "nsteps": nsteps, "restart_every": restart_every, "out": workdir / "forces.dump",
        "dump_every": 1,
    }
    run = run_lmp((INPUTS / "in.corotating_paths").read_text(), workdir, nprocs=nprocs, variables=variables,
                  expect_error=expect_error, timeout=900)
    if expect_error:
        return run, []
    run.assert_clean()
    return run, read_dump(workdir / "forces.dump")


def read_dump(path: Path) -> list[tuple[int, np.ndarray]]:
    """(step, rows of the dump's columns, sorted by id) per frame."""
    frames = []
    lines = path.read_text().splitlines()
    i = 0
    while i < len(lines):
        step = int(lines[i + 1])
        count = int(lines[i + 3])
        rows = np.array([[float(v) for v in line.split()] for line in lines[i + 9:i + 9 + count]])
        frames.append((step, rows))
        i += 9 + count
    return frames


def compare(reference, other, first_step: int = 1) -> dict[str, float]:
    """Largest relative force/torque difference over contacts above SMALL_SHARE of the step's largest
    force, and the largest absolute difference of the others in units of that force."""
    reference = {step: rows for step, rows in reference}
    worst_rel, worst_abs, contacts = 0.0, 0.0, 0
    for step, rows in other:
        if step < first_step:
            continue
        ref = reference[step]
        assert np.array_equal(ref[:, 0], rows[:, 0]), f"step {step}: different particles"
        for cols in (slice(4, 7), slice(7, 10)):
            a, b = ref[:, cols], rows[:, cols]
            size = np.linalg.norm(a, axis=1)
            diff = np.linalg.norm(a - b, axis=1)
            scale = size.max()
            if scale == 0.0:
                assert diff.max() == 0.0, f"step {step}: force where the reference has none"
                continue
            large = size > SMALL_SHARE * scale
            contacts += int(large.sum())
            if large.any():
                worst_rel = max(worst_rel, float((diff[large] / size[large]).max()))
            if (~large).any():
                worst_abs = max(worst_abs, float(diff[~large].max() / scale))
    return {"relative": worst_rel, "absolute": worst_abs, "contacts": contacts}


def touched(frames, x_lo: float, x_hi: float) -> int:
    """Particles with a non-zero force whose centre lies in [x_lo, x_hi) at some step."""
    ids = set()
    for _, rows in frames[1:]:
        inside = (rows[:, 1] >= x_lo) & (rows[:, 1] < x_hi) & (np.linalg.norm(rows[:, 4:7], axis=1) > 0)
        ids.update(rows[inside, 0].astype(int).tolist())
    return len(ids)


# ---- force equality with the stock path -----------------------------------------------------------

def test_forces_equal_stock_on_conveying_kneading_and_chopping_elements(tmp_path, element_meshes):
    atoms = atoms_in_bores(np.random.default_rng(7), 200, [(-0.0005, 0.0465)])
    _, stock = run_paths(tmp_path / "stock", "stock", element_meshes, atoms, periodic=False, nsteps=150)
    _, corotating = run_paths(tmp_path / "corotating", "corotating", element_meshes, atoms, periodic=False,
                              nsteps=150)
    result = compare(stock, corotating)
    print("elements:", result)
    # zones of corotating-elements.spec: conveying 0-12.5 mm, kneading 12.5-25, chopping 25-33.3
    for name, lo, hi in (("conveying", 0.0, 0.0125), ("kneading", 0.0125, 0.025), ("chopping", 0.025, 0.0333)):
        assert touched(stock, lo, hi) >= 3, f"too few particles touched the {name} element to compare"
    assert result["contacts"] > 1000
    assert result["relative"] <= RELATIVE, result
    assert result["absolute"] <= ABSOLUTE_SHARE, result


def test_forces_equal_stock_across_periodic_boundaries(tmp_path, periodic_meshes):
    # every particle within 2 mm of a periodic face: contacts through the periodic images
    atoms = atoms_in_bores(np.random.default_rng(11), 200,
                           [(0.0, 0.002), (PERIODIC_LENGTH - 0.002, PERIODIC_LENGTH)])
    _, stock = run_paths(tmp_path / "stock", "stock", periodic_meshes, atoms, periodic=True, nsteps=150)
    _, corotating = run_paths(tmp_path / "corotating", "corotating", periodic_meshes, atoms, periodic=True,
                              nsteps=150)
    result = compare(stock, corotating)
    print("periodic:", result)
    assert touched(stock, 0.0, 0.0005) >= 3 and touched(stock, PERIODIC_LENGTH - 0.0005, PERIODIC_LENGTH) >= 3
    assert result["contacts"] > 1000
    assert result["relative"] <= RELATIVE, result
    assert result["absolute"] <= ABSOLUTE_SHARE, result


# ---- MPI and restarts ----------------------------------------------------------------------------

@pytest.mark.parametrize("nprocs", [2, 4])
def test_ranks_agree(tmp_path, periodic_meshes, nprocs):
    """Particles slide 1.8 mm along the axis and 0.6 mm across it, through the subdomain boundaries
    (and the periodic boundary), carrying their contact history with them, while touching the screws."""
    atoms = atoms_in_bores(np.random.default_rng(13), 800, [(0.0, PERIODIC_LENGTH)])
    velocity = (3.0, 1.0, -0.01)
    _, serial = run_paths(tmp_path / "np1", "corotating", periodic_meshes, atoms, periodic=True, nsteps=300,
                          velocity=velocity)
    _, parallel = run_paths(tmp_path / f"np{nprocs}", "corotating", periodic_meshes, atoms, periodic=True,
                            nsteps=300, nprocs=nprocs, velocity=velocity)
    result = compare(serial, parallel, first_step=0)
    print(f"np {nprocs}:", result)
    # subdomain boundaries: x = L/2 (2 ranks: 2x1x1), and also y = 0 (4 ranks: 2x2x1)
    crossing = 0
    for (_, before), (_, after) in zip(parallel[:-1], parallel[1:]):
        in_contact = np.linalg.norm(after[:, 4:7], axis=1) > 0
        crossed_x = (before[:, 1] < PERIODIC_LENGTH / 2) != (after[:, 1] < PERIODIC_LENGTH / 2)
        crossed_y = (before[:, 2] < 0.0) != (after[:, 2] < 0.0)
        crossing += int((in_contact & (crossed_x | (crossed_y if nprocs == 4 else False))).sum())
    print("subdomain crossings while in contact:", crossing)
    assert crossing >= 5
    assert result["contacts"] > 1000
    assert result["relative"] <= 1e-12 and result["absolute"] <= 1e-14, result


def test_restart_continues_the_same_run(tmp_path, periodic_meshes):
    """Angle and contact history go through the restart file: the continued run equals the unbroken one."""
    atoms = atoms_in_bores(np.random.default_rng(17), 200, [(0.0, PERIODIC_LENGTH)])
    _, whole = run_paths(tmp_path / "whole", "corotating", periodic_meshes, atoms, periodic=True, nsteps=300,
                         restart_every=150)
    restart = tmp_path / "whole" / "restart.150"
    assert restart.exists()
    _, continued = run_paths(tmp_path / "continued", "corotating", periodic_meshes, "", periodic=True,
                             nsteps=150, nprocs=2, restart_from=restart)
    assert continued[0][0] == 150 and continued[-1][0] == 300
    # step 150 is the setup of the continued run (no history update), from 151 on they must agree
    result = compare(whole, continued, first_step=151)
    print("restart:", result)
    assert result["contacts"] > 500
    assert result["relative"] <= 1e-12 and result["absolute"] <= 1e-14, result


# ---- bad input --------------------------------------------------------------------------------------

def drive(screw1_origin_y: str = "-${half_centre}", extra: str = "", period: str = "${period}") -> str:
    return ("fix walls all wall/gran/corotating model hertz tangential history rolling_friction cdt "
            "mesh n_meshes 3 meshes screw1 screw2 barrel fixed barrel "
            f"corotate screw1 origin 0 {screw1_origin_y} 0 axis 1 0 0 period {period} "
            "corotate screw2 origin 0 ${half_centre} 0 axis 1 0 0 period ${period}\n" + extra)


@pytest.mark.parametrize("case, text, message", [
    ("off axis", drive(screw1_origin_y="-0.0076"),
     "mesh 'screw1' does not share the rotation axis"),
    ("also moved", drive(extra="fix turn1 all move/mesh mesh screw1 rotate origin 0 -${half_centre} 0 "
                               "axis 1 0 0 period ${period}\n"),
     "mesh 'screw1' is also moved by another fix"),
    ("zero period", drive(period="0"), "period = 0 is not allowed"),
    ("unknown keyword", drive().replace("corotate screw2", "spin screw2"), "unknown keyword 'spin'"),
])
def test_rejects_screws_that_do_not_turn_rigidly_about_their_axis(tmp_path, periodic_meshes, case, text, message):
    atoms = atoms_in_bores(np.random.default_rng(19), 5, [(0.0, PERIODIC_LENGTH)])
    run, _ = run_paths(tmp_path, "corotating", periodic_meshes, atoms, periodic=True, nsteps=10,
                       extra_drive=text, expect_error=True)
    text_out = run.stdout + run.stderr + run.log
    assert message in text_out, f"{case}: expected '{message}' in the error, got {run.errors}"


# ---- outputs ------------------------------------------------------------------------------------------

def stl_vertices(path: Path) -> np.ndarray:
    return np.array([[float(v) for v in line.split()[1:4]] for line in path.read_text().splitlines()
                     if line.lstrip().startswith("vertex")])


def vtk_points(path: Path) -> np.ndarray:
    lines = path.read_text().splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("POINTS"))
    count = int(lines[start].split()[1])
    return np.array([[float(v) for v in line.split()] for line in lines[start + 1:start + 1 + count]])


def test_screw_dump_is_the_mesh_turned_by_omega_t(tmp_path, periodic_meshes):
    """screw_dump writes screw 1 at step 100 as the STL turned by ω · 100 dt about its axis."""
    atoms = atoms_in_bores(np.random.default_rng(29), 5, [(0.0, PERIODIC_LENGTH)])
    text = drive(extra="").replace("fixed barrel ", "fixed barrel screw_dump 50 ${restart_file}_dump ")
    run_paths(tmp_path, "corotating", periodic_meshes, atoms, periodic=True, nsteps=100, extra_drive=text)
    dumped = vtk_points(tmp_path / "restart_dump_screw1_100.vtk")
    theta = 2 * np.pi / 0.1 * 100 * 2e-6
    c, s = np.cos(theta), np.sin(theta)
    nodes = stl_vertices(periodic_meshes / "screw1.stl")
    y, z = nodes[:, 1] + HALF_CENTRE, nodes[:, 2]
    expected = np.column_stack([nodes[:, 0], c * y - s * z - HALF_CENTRE, s * y + c * z])
    assert dumped.shape == expected.shape
    order = lambda a: a[np.lexsort(np.round(a / 1e-9).T[::-1])]  # noqa: E731 - same points, any order
    assert np.abs(order(dumped) - order(expected)).max() < 1e-12


def test_more_screw_contacts_than_max_contacts_is_a_clear_error(tmp_path, periodic_meshes):
    atoms = atoms_in_bores(np.random.default_rng(31), 200, [(0.0, PERIODIC_LENGTH)])
    text = drive().replace("fixed barrel ", "fixed barrel max_contacts 1 ")
    run, _ = run_paths(tmp_path, "corotating", periodic_meshes, atoms, periodic=True, nsteps=50,
                       extra_drive=text, expect_error=True)
    assert "screw triangles at once; raise max_contacts" in run.stdout + run.stderr + run.log
    assert "max_contacts = 1" in run.stdout + run.stderr + run.log


def test_per_particle_wall_force_output_equals_the_stock_one(tmp_path, periodic_meshes):
    """fix wall/gran's store_force (per-particle wall force) works for the corotating meshes too."""
    atoms = atoms_in_bores(np.random.default_rng(37), 150, [(0.0, PERIODIC_LENGTH)])
    output = ("dump wallforce all custom 1 ${restart_file}_wallforce id f_force_walls[1] f_force_walls[2] "
              "f_force_walls[3]\ndump_modify wallforce sort id format \"%d %.17g %.17g %.17g\"\n")
    frames = {}
    # the corotating fix's output vector: force on screw 1, screw 2 and the barrel (7 values each)
    loads = ('fix loads all print 1 "$(step) ' + " ".join(f"$(f_walls[{7 * m + k}])" for m in range(3) for k in (1, 2, 3))
             + '" file ${restart_file}_loads screen no\n')
    for name in ("stock", "corotating"):
        text = (INPUTS / f"drive_{name}.in").read_text().replace(
            "rolling_friction cdt", "rolling_friction cdt store_force yes", 1) + output
        if name == "corotating":
            text += loads
        run_paths(tmp_path / name, name, periodic_meshes, atoms, periodic=True, nsteps=100, extra_drive=text)
        frames[name] = read_dump(tmp_path / name / "restart_wallforce")
    # action and reaction: the meshes' total force is minus the sum of the particles' wall forces
    loads_table = np.loadtxt(tmp_path / "corotating" / "restart_loads")
    for step, rows in frames["corotating"][1:]:
        on_meshes = loads_table[loads_table[:, 0] == step, 1:].reshape(3, 3).sum(axis=0)
        on_particles = rows[:, 1:].sum(axis=0)
        assert np.allclose(on_meshes, -on_particles, rtol=1e-12, atol=1e-12 * np.abs(rows[:, 1:]).sum()), step
    worst, compared = 0.0, 0
    for (step, stock), (_, corotating) in zip(frames["stock"][1:], frames["corotating"][1:]):
        size = np.linalg.norm(stock[:, 1:], axis=1)
        large = size > SMALL_SHARE * size.max()
        compared += int(large.sum())
        worst = max(worst, float((np.linalg.norm(stock[:, 1:] - corotating[:, 1:], axis=1)[large] / size[large]).max()))
    print("store_force:", worst, compared)
    assert compared > 500 and worst <= RELATIVE

