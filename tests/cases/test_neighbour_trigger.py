"""`neigh_modify trigger pairwise` (patches/neighbor-cpp.patch over physics/neighbour_trigger.h):
fewer neighbour-list builds than the stock half-skin rule, and not one contact missed. The reference
rebuilds the lists every step (`every 1 check no`: nothing can be missed); a lattice of resting
particles is crossed by two fast ones far apart, elastic Hertz contacts, periodic box. A run whose lists
are too old (`every 250 check no`: 1.25 mm at 5 m/s, beyond the skin) must differ from the reference: the comparison sees a missed
contact."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from crafted_scenes import DENSITY, PLANE, RADIUS, header
from tsg_harness import run_lmp

STEPS = 12000
SKIN = 0.0005   # crafted_scenes.MATERIAL's neighbour skin


def lattice_scene(neigh: str, processors: str | None = None) -> str:
    """8 x 3 particles at rest in the plane z = 0 (spacing 2.5 mm), one crossing it at 5 m/s along x
    1.6 mm beside a row (glancing contacts), one at -4 m/s 5 mm above: two fast particles far apart."""
    atoms = [(-0.00875 + 0.0025 * i, -0.0025 + 0.0025 * j, 0.0) for i in range(8) for j in range(3)]
    atoms += [(-0.0075, -0.0041, 0.0), (0.009, 0.0, 0.005)]
    creates = "".join(f"create_atoms 1 single {x!r} {y!r} {z!r} units box\n" for x, y, z in atoms)
    n = len(atoms)
    return header(processors, boundary="p p p") + creates + f"""set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
neigh_modify {neigh}
group fast1 id {n - 1}
group fast2 id {n}
velocity fast1 set 5 0 0 units box
velocity fast2 set -4 0 0 units box
fix integrate all nve/sphere
timestep 1e-6
thermo_style custom step atoms ke
thermo 2000
run {STEPS}
write_dump all custom final.txt id x y z vx vy vz modify sort id format "%d %.17g %.17g %.17g %.17g %.17g %.17g"
"""


def final_state(workdir: Path) -> np.ndarray:
    lines = (workdir / "final.txt").read_text().splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("ITEM: ATOMS")) + 1
    return np.array([[float(v) for v in line.split()] for line in lines[start:]])


def builds(log: str) -> int:
    return int(next(line for line in log.splitlines() if line.startswith("Neighbor list builds")).split("=")[1])


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[np.ndarray, int]]:
    variants = {"every_step": ("delay 0 every 1 check no", 1), "half": ("delay 0 trigger half", 1),
                "pairwise": ("delay 0 trigger pairwise", 1), "pairwise_2_ranks": ("delay 0 trigger pairwise", 2),
                "too_old": ("delay 0 every 250 check no", 1)}
    out = {}
    for name, (neigh, nprocs) in variants.items():
        workdir = tmp_path_factory.mktemp(name)
        run = run_lmp(lattice_scene(neigh, "2 1 1" if nprocs == 2 else None), workdir, nprocs=nprocs)
        out[name] = (final_state(workdir), builds(run.log))
    return out


def position_error(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance between the same particle in two final states (periodic box of 0.02 m)."""
    d = a[:, 1:4] - b[:, 1:4]
    d -= 0.02 * np.round(d / 0.02)
    return float(np.max(np.linalg.norm(d, axis=1)))


def test_the_fast_particles_hit_the_lattice(runs: dict[str, tuple[np.ndarray, int]]) -> None:
    state, _ = runs["every_step"]
    assert np.count_nonzero(np.linalg.norm(state[:24, 4:7], axis=1) > 0.1) >= 4   # lattice particles set moving
    assert abs(state[24, 4] - 5.0) > 1.0                                            # the fast one deflected


def test_pairwise_misses_no_contact_on_one_and_two_ranks(runs: dict[str, tuple[np.ndarray, int]]) -> None:
    reference, _ = runs["every_step"]
    for name in ("half", "pairwise", "pairwise_2_ranks"):
        assert position_error(runs[name][0], reference) < 1e-9, name


def test_old_lists_are_seen_by_the_comparison(runs: dict[str, tuple[np.ndarray, int]]) -> None:
    assert position_error(runs["too_old"][0], runs["every_step"][0]) > 1e-6


def test_pairwise_builds_fewer_lists_than_the_half_skin_rule(runs: dict[str, tuple[np.ndarray, int]]) -> None:
    # the stock rule rebuilds each time the 5 m/s particle has moved half a skin (50 steps: 240 builds
    # if it kept its speed; its collisions slow it); the pairwise rule lets it cross up to the whole
    # skin while the others stay within skin - d_max
    half, pairwise = runs["half"][1], runs["pairwise"][1]
    assert half >= 0.6 * STEPS * 5.0 * 1e-6 / (0.5 * SKIN)
    assert pairwise <= 0.7 * half
    assert runs["pairwise_2_ranks"][1] == pairwise   # the same global decision on every rank


def test_bad_trigger_and_mesh_lists_are_refused(tmp_path: Path) -> None:
    bad = run_lmp(header() + "neigh_modify trigger quarter\n", tmp_path / "bad", expect_error=True)
    assert "neigh_modify trigger quarter is not allowed: half" in bad.log + bad.stdout
    # a stock mesh wall keeps a list valid for half a skin only
    mesh = run_lmp(header() + f"""neigh_modify trigger pairwise
fix plane all mesh/surface file plane.stl type 1
fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes plane
create_atoms 1 single 0 0 0.002 units box
set atom * diameter {2 * RADIUS!r} density {DENSITY!r}
fix integrate all nve/sphere
timestep 1e-6
run 10
""", tmp_path / "mesh", files={"plane.stl": PLANE}, expect_error=True)
    assert "neigh_modify trigger pairwise is not allowed with fix" in mesh.log + mesh.stdout
    assert "use trigger half" in mesh.log + mesh.stdout
