"""fix massflow/planes: signed mass flow rates in kg/h over a window, periodic crossings, open
domain, the file and the thermo vector; and why stock fix massflow/mesh is not used for this."""
import math
import re

import numpy as np
import pytest

from measure_cases import BASE, DENSITY, RESTART_BASE, Mover, lanes, plane_stl, variables
from tsg_harness import run_lmp

DT = 1e-4
WINDOW = 5000                    # steps: 0.5 s
T_WINDOW = WINDOW * DT
LENGTH = 0.1


def movers_input(movers: list[Mover], radii: list[float], fixes: str, nsteps: int, thermo: str) -> str:
    lines = [BASE]
    for k, (m, r) in enumerate(zip(movers, radii), start=1):
        lines.append(f"create_atoms 1 single {m.x0!r} {m.y!r} {m.z!r} units box")
        lines.append(f"set atom {k} diameter {2 * r!r} density {DENSITY!r}")
    lines.append("velocity all set 0 0 0 units box")
    for k, m in enumerate(movers, start=1):
        lines.append(f"set atom {k} vx {m.v!r}")
    lines.append("fix integr all nve/sphere")
    lines.append(fixes)
    lines.append(f"timestep {DT}\nthermo_style custom step {thermo}\nthermo_modify format float %.15g\n"
                 f"thermo {WINDOW}\nrun {nsteps}\n")
    return "\n".join(lines)


def mass(r: float) -> float:
    return DENSITY * 4 / 3 * math.pi * r**3


def read_flow(path):
    lines = path.read_text().splitlines()
    header = [l for l in lines if l.startswith("#")]
    rows = np.array([[float(v) for v in l.split()] for l in lines if not l.startswith("#")])
    return header, rows


def test_periodic_rates_are_signed_and_exact(tmp_path):
    # speeds k L / T_window: each particle crosses each plane exactly k times per window
    grid = lanes(8)
    plan = [(0.011, 1, 5e-4), (0.037, 2, 5e-4), (0.064, 1, 3e-4), (0.081, -1, 5e-4), (0.093, 3, 3e-4),
            (0.0515, -2, 3e-4)]
    movers = [Mover(x0, k * LENGTH / T_WINDOW, *grid[j]) for j, (x0, k, _) in enumerate(plan)]
    radii = [r for *_, r in plan]
    fixes = "fix mf all massflow/planes planes 3 0.0 0.03 0.0705 window 5000 file flow.txt"
    run = run_lmp(movers_input(movers, radii, fixes, 3 * WINDOW, "f_mf[1] f_mf[2] f_mf[3]"), tmp_path,
                  variables=variables(True), files={})
    run.assert_clean()
    expected = sum(k * mass(r) for _, k, r in plan) / T_WINDOW * 3600   # kg/h, every plane, every window
    header, rows = read_flow(tmp_path / "flow.txt")
    assert header[0] == "# tsg-dem mass flow v1"
    assert header[-1] == "# columns: step time sensor_1 sensor_2 sensor_3"
    np.testing.assert_array_equal(rows[:, 0], [5000, 10000, 15000])
    np.testing.assert_allclose(rows[:, 1], [0.5, 1.0, 1.5], rtol=1e-12)
    np.testing.assert_allclose(rows[:, 2:], expected, rtol=1e-9)   # the file has 10 digits
    thermo = run.thermo[-1]
    for k in (1, 2, 3):
        assert thermo[f"mf[{k}]"][0] == 0.0                         # no window completed yet
        np.testing.assert_allclose(thermo[f"mf[{k}]"][1:], expected, rtol=1e-12)
    print(f"[ measured ] periodic mass flow {thermo['mf[1]'][-1]:.10g} kg/h, expected {expected:.10g} kg/h")


def test_open_domain_counts_each_crossing_in_its_window(tmp_path):
    grid = lanes(6)
    plan = [(0.001, 0.07), (0.004, 0.11), (0.0095, 0.023), (0.0503, -0.06), (0.079, -0.13)]
    movers = [Mover(x0, v, *grid[j]) for j, (x0, v) in enumerate(plan)]
    r = 5e-4
    planes = (0.02, 0.06)
    fixes = "fix mf all massflow/planes planes 2 0.02 0.06 window 5000 file flow.txt"
    nsteps = 4 * WINDOW
    run = run_lmp(movers_input(movers, [r] * len(movers), fixes, nsteps, "f_mf[1] f_mf[2]"), tmp_path,
                  variables=variables(False))
    run.assert_clean()
    _, rows = read_flow(tmp_path / "flow.txt")
    expected = np.zeros((4, 2))
    for x0, v in plan:
        for j, plane in enumerate(planes):
            t = (plane - x0) / v
            if 0 < t < nsteps * DT:
                expected[int(t // T_WINDOW), j] += math.copysign(mass(r), v)
    expected *= 3600 / T_WINDOW
    assert np.count_nonzero(expected) >= 4 and (expected < 0).any() and (expected > 0).any()
    np.testing.assert_allclose(rows[:, 2:], expected, rtol=1e-9, atol=1e-12)


def test_backflow_across_a_sensor_cancels_unlike_stock_massflow_mesh(tmp_path):
    # a particle oscillating across x = 0.05 (amplitude 2 mm, period 0.1 s) for 5 whole periods: the
    # net mass through the plane is zero. fix massflow/mesh counts only one direction ("count
    # multiple" adds every forward crossing), which is why the sensors are a fix of their own.
    text = BASE + f"""create_atoms 1 single 0.05 0 0 units box
set atom 1 diameter 0.001 density {DENSITY!r}
fix wig all move wiggle 0.002 0 0 0.1
fix mf all massflow/planes planes 1 0.05 window 5000
fix plane all mesh/surface file plane.stl type 1
fix stock all massflow/mesh mesh plane vec_side 1 0 0 count multiple
timestep {DT}
thermo_style custom step f_mf[1] f_stock[1]
thermo_modify format float %.15g
thermo 5000
run 5000
"""
    run = run_lmp(text, tmp_path, variables=variables(False), files={"plane.stl": plane_stl(0.05)})
    run.assert_clean()
    thermo = run.thermo[-1]
    assert thermo["mf[1]"][-1] == pytest.approx(0.0, abs=1e-15)
    counted = thermo["stock[1]"][-1]   # mass counted by fix massflow/mesh, kg
    # 5 forward crossings; the first one is not counted (the particle starts on the plane and
    # massflow/mesh only records which side it is on when it first sees it)
    n = counted / mass(5e-4)
    assert n == pytest.approx(round(n), abs=1e-9) and round(n) == 4, n
    print(f"[ measured ] oscillating particle: massflow/planes net {thermo['mf[1]'][-1]} kg/h; "
          f"massflow/mesh 'count multiple' {counted:.4g} kg = {n:.0f} particle masses")


def test_a_restart_continues_at_planes_equal_within_a_nanometre(tmp_path):
    """A domain length written with 11 or 13 digits (zones.txt against in.tsg_periodic's default) moves
    a plane by ~1e-13 m: the same sensors, continued, and the second window's rate is exact. A plane
    moved by 2 nm is another sensor: refused, with the shift named (the positions print alike)."""
    grid = lanes(3)
    plan = [(0.011, 1, 5e-4), (0.037, 2, 5e-4), (0.064, -1, 3e-4)]
    movers = [Mover(x0, k * LENGTH / T_WINDOW, *grid[j]) for j, (x0, k, _) in enumerate(plan)]
    first = movers_input(movers, [r for *_, r in plan], "fix mf all massflow/planes planes 2 0.0 0.0958333333333 "
                         "window 5000 file flow.txt", WINDOW, "f_mf[1]") + "write_restart state.restart\n"
    run_lmp(first, tmp_path, variables=variables(True), files={}).assert_clean()
    expected = sum(k * mass(r) for _, k, r in plan) / T_WINDOW * 3600

    def second(plane: float, expect_error: bool):
        text = (RESTART_BASE + "fix integr all nve/sphere\n"
                f"fix mf all massflow/planes planes 2 0.0 {plane!r} window 5000 file flow.txt\n"
                f"timestep {DT}\nthermo_style custom step f_mf[1] f_mf[2]\nthermo_modify format float %.15g\n"
                f"thermo {WINDOW}\nrun {WINDOW}\n")
        return run_lmp(text, tmp_path, variables=variables(True), expect_error=expect_error)

    continued = second(0.095833333333, expect_error=False)
    continued.assert_clean()
    np.testing.assert_allclose(continued.thermo[-1]["mf[2]"][-1], expected, rtol=1e-12)
    moved = second(0.0958333353333, expect_error=True)
    message = moved.stdout + moved.log
    shift = re.search(r"this fix has planes 2 0 0\.09583333533 \(moved by up to (\S+) m; allowed: 1e-09 m\)", message)
    assert shift and float(shift.group(1)) == pytest.approx(2e-9, rel=1e-6), message[-2000:]
