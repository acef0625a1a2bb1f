"""compute element/stats: solid fraction of a known static arrangement (spheres cut by zone
boundaries and by the periodic boundary) against spherical-cap volumes computed here, mass-weighted
velocities, counts and masses; the same on 1, 2 and 4 ranks; time averages with fix ave/time."""
import math

import numpy as np
import pytest

from measure_cases import BASE, DENSITY, lanes, sphere_slab_volume_reference, variables, zones_text
from tsg_harness import run_lmp

# zones that tile the periodic box [0, 0.1): spheres at the box ends belong to zones 1 and 4
TILING = [(1, "conveying", 0.0, 0.03, 3.0e-6), (2, "kneading", 0.03, 0.045, 1.5e-6),
          (3, "kneading", 0.045, 0.06, 1.2e-6), (4, "chopping", 0.06, 0.1, 4.0e-6)]
LENGTH = 0.1

# (x, radius, vx, vy, vz): inside zones, cut by zone boundaries (centre on either side, or on it),
# cut by the periodic boundary at both ends, two sizes
SPHERES = [
    (0.015, 5e-4, 0.10, 0.00, 0.00),
    (0.0297, 5e-4, 0.20, 0.05, 0.00),    # cut by 0.03, mostly in zone 1
    (0.0302, 5e-4, -0.10, 0.00, 0.30),   # cut by 0.03, mostly in zone 2
    (0.045, 3e-4, 0.05, 0.05, 0.05),     # centred on the 0.045 boundary: half and half
    (0.0448, 3e-4, 0.15, 0.00, 0.00),
    (0.0601, 5e-4, 0.00, 0.20, 0.00),
    (0.05, 3e-4, 0.40, 0.00, 0.00),
    (0.0996, 5e-4, 0.25, 0.00, 0.00),    # sticks out through x = 0.1 into zone 1
    (0.0002, 3e-4, -0.30, 0.10, 0.00),   # sticks out through x = 0 into zone 4
    (0.08, 5e-4, 0.0, 0.0, 0.0),         # at rest
]


def static_input() -> str:
    grid = lanes(len(SPHERES))
    lines = [BASE]
    for k, (x, r, vx, vy, vz) in enumerate(SPHERES, start=1):
        y, z = grid[k - 1]
        lines.append(f"create_atoms 1 single {x!r} {y!r} {z!r} units box")
        lines.append(f"set atom {k} diameter {2 * r!r} density {DENSITY!r}")
    lines.append("velocity all set 0 0 0 units box")
    for k, (x, r, vx, vy, vz) in enumerate(SPHERES, start=1):
        lines.append(f"set atom {k} vx {vx!r} vy {vy!r} vz {vz!r}")
    # no time integration: the arrangement stays where it is
    lines.append("compute es all element/stats zones zones.txt")
    cols = " ".join(f"c_es[{z}][{c}]" for z in range(1, 5) for c in range(1, 8))
    lines.append(f"thermo_style custom step {cols}\nthermo_modify format float %.17g\nthermo 1\nrun 2\n")
    return "\n".join(lines)


def expected_table() -> np.ndarray:
    """Rows: zones; columns: solid fraction, mean speed, mean vx, count, mass, mass x speed, momentum."""
    out = np.zeros((len(TILING), 7))
    for z, (_, _, xs, xe, free) in enumerate(TILING):
        volume = mass = mass_speed = mass_vx = count = 0.0
        for x, r, vx, vy, vz in SPHERES:
            m = DENSITY * 4 / 3 * math.pi * r**3
            v = sum(image for image in (sphere_slab_volume_reference(x + shift, r, xs, xe)
                                        for shift in (-LENGTH, 0.0, LENGTH)))
            f = v / (4 / 3 * math.pi * r**3)
            volume += v
            mass += f * m
            mass_speed += f * m * math.sqrt(vx * vx + vy * vy + vz * vz)
            mass_vx += f * m * vx
            count += 1 if xs <= x < xe else 0
        out[z] = [volume / free, mass_speed / mass if mass else 0, mass_vx / mass if mass else 0, count, mass,
                  mass_speed, mass_vx]
    return out


def measured_table(run) -> np.ndarray:
    thermo = run.thermo[-1]
    return np.array([[thermo[f"es[{z}][{c}]"][-1] for c in range(1, 8)] for z in range(1, 5)])


def test_static_arrangement_matches_spherical_caps(tmp_path):
    run = run_lmp(static_input(), tmp_path, variables=variables(True), files={"zones.txt": zones_text(TILING)})
    run.assert_clean()
    got, want = measured_table(run), expected_table()
    # every zone has matter in it, and the boundary spheres really are split
    assert np.all(want[:, 0] > 0) and want[:, 3].sum() == len(SPHERES)
    np.testing.assert_allclose(got[:, 0], want[:, 0], rtol=1e-9, atol=0, err_msg="solid fraction")
    np.testing.assert_allclose(got[:, 4], want[:, 4], rtol=1e-9, atol=0, err_msg="mass")
    np.testing.assert_allclose(got[:, 1:3], want[:, 1:3], rtol=1e-9, atol=1e-15, err_msg="velocities")
    np.testing.assert_allclose(got[:, 5:], want[:, 5:], rtol=1e-9, atol=1e-20, err_msg="mass x velocities")
    np.testing.assert_array_equal(got[:, 3], want[:, 3])
    # the matter in the zones is all of it (the zones tile the box)
    total_mass = sum(DENSITY * 4 / 3 * math.pi * r**3 for _, r, *_ in SPHERES)
    assert got[:, 4].sum() == pytest.approx(total_mass, rel=1e-12)
    print(f"[ measured ] solid fractions {got[:, 0]}, largest relative error "
          f"{np.max(np.abs(got[:, 0] / want[:, 0] - 1)):.2g}")


def test_same_statistics_on_1_2_and_4_ranks(tmp_path):
    tables = {}
    for nprocs in (1, 2, 4):
        run = run_lmp(static_input(), tmp_path / f"np{nprocs}", nprocs=nprocs,
                      variables=variables(True, px=nprocs), files={"zones.txt": zones_text(TILING)})
        tables[nprocs] = measured_table(run)
    for nprocs in (2, 4):
        np.testing.assert_allclose(tables[nprocs], tables[1], rtol=1e-13, atol=1e-18)


def read_ave_time_vector(path) -> dict[int, np.ndarray]:
    blocks, lines = {}, [l for l in path.read_text().splitlines() if not l.startswith("#")]
    k = 0
    while k < len(lines):
        step, nrows = (int(v) for v in lines[k].split())
        blocks[step] = np.array([[float(v) for v in l.split()[1:]] for l in lines[k + 1:k + 1 + nrows]])
        k += 1 + nrows
    return blocks


def test_time_average_with_fix_ave_time_over_a_moving_particle(tmp_path):
    # one sphere moving at 0.05 m/s through the zones: the window average of its solid fraction per
    # zone equals the average of the exact volumes at the sampled steps
    text = BASE + """create_atoms 1 single 0.0285 0 0 units box
set atom 1 diameter 0.001 density 2500
velocity all set 0.05 0 0 units box
fix integr all nve/sphere
compute es all element/stats zones zones.txt
fix avg all ave/time 10 5 50 c_es[1] c_es[2] c_es[3] c_es[4] c_es[5] c_es[6] c_es[7] mode vector file elements.txt
timestep 1e-4
variable a11 equal f_avg[1][1]
variable a21 equal f_avg[2][1]
variable a13 equal f_avg[1][3]
variable a15 equal f_avg[1][5]
variable a17 equal f_avg[1][7]
fix pr all print 50 "$(step) ${a11} ${a21} ${a13} ${a15} ${a17}" file averages.txt screen no title none
thermo_style custom step c_es[1][1] c_es[2][1]
thermo_modify format float %.17g
thermo 10
run 600
"""
    run = run_lmp(text, tmp_path, variables=variables(True), files={"zones.txt": zones_text(TILING)})
    run.assert_clean()
    blocks = read_ave_time_vector(tmp_path / "elements.txt")
    assert sorted(blocks) == list(range(50, 601, 50))
    thermo = run.thermo[-1]
    r, v = 5e-4, 0.05
    printed = {int(float(l.split()[0])): np.array([float(x) for x in l.split()[1:]])
               for l in (tmp_path / "averages.txt").read_text().splitlines() if l.strip()}
    for step, table in blocks.items():
        samples = [step - 40, step - 30, step - 20, step - 10, step]
        averaged = printed[step][:2]   # 15 digits
        # the file holds the same numbers, printed with 6 digits
        np.testing.assert_allclose(table[:2, 0], averaged, rtol=1e-5, atol=1e-12)
        # the mean of the compute at the sampled steps
        rows = [np.where(thermo["Step"] == s)[0][0] for s in samples]
        np.testing.assert_allclose(averaged[0], np.mean(thermo["es[1][1]"][rows]), rtol=1e-12, atol=1e-18)
        # and the mean of the exact volumes at the sampled positions
        for z, (_, _, xs, xe, free) in enumerate(TILING[:2]):
            exact = np.mean([sphere_slab_volume_reference(0.0285 + v * s * 1e-4, r, xs, xe) / free for s in samples])
            assert averaged[z] == pytest.approx(exact, rel=1e-9, abs=1e-15)
        # mean axial velocity: the plain average counts samples with zone 1 empty as 0, the
        # mass-weighted one (axial momentum / mass) is the particle's speed whenever zone 1 had matter
        occupied = sum(sphere_slab_volume_reference(0.0285 + v * s * 1e-4, r, 0.0, 0.03) > 0 for s in samples)
        assert printed[step][2] == pytest.approx(v * occupied / 5, rel=1e-12, abs=1e-15)
        if occupied:
            assert printed[step][4] / printed[step][3] == pytest.approx(v, rel=1e-12)
