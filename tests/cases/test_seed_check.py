"""cases/seed_check.py and the particle–barrel overlap monitor (cases/include/barrel_overlap.in):
the monitor against distances to a densely sampled twin-bore wall, the log reading on a crafted
log, and a two-seed run of the demo case over a very short window."""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(ROOT / "cases"))
import seed_check  # noqa: E402

LMP = os.environ.get("TSG_LMP", str(ROOT / "build" / "lmp"))
HALF_CENTRE = 0.019310 / 2     # a/2, m (seed paper Table 1)
BORE = 0.0125                  # bore radius, m
CUSP_Z = np.sqrt(BORE ** 2 - HALF_CENTRE ** 2)

# (y, z, radius): mid-bore wall, other bore, both sides of a cusp, outside the barrel, the axis
PARTICLES = [(-HALF_CENTRE, BORE - 3e-4, 5e-4),
             (HALF_CENTRE + (BORE - 4.5e-4) * np.cos(-1.0), (BORE - 4.5e-4) * np.sin(-1.0), 5e-4),
             (0.0, CUSP_Z - 2e-4, 5e-4),
             (-3e-4, -(CUSP_Z + 1e-4), 5e-4),
             (2e-4, CUSP_Z - 1e-3, 4e-4),
             (-HALF_CENTRE, -(BORE + 1e-4), 5e-4),
             (-HALF_CENTRE, 0.0, 5e-4)]


def sampled_wall_overlap(y: float, z: float, radius: float) -> float:
    """δ/r against the twin-bore wall sampled every 0.2 µm (arc points outside the other bore)."""
    angle = np.linspace(0.0, 2 * np.pi, 400_000, endpoint=False)
    walls = []
    for centre, other in ((-HALF_CENTRE, HALF_CENTRE), (HALF_CENTRE, -HALF_CENTRE)):
        wy, wz = centre + BORE * np.cos(angle), BORE * np.sin(angle)
        keep = (wy - other) ** 2 + wz ** 2 >= BORE ** 2
        walls.append(np.column_stack((wy[keep], wz[keep])))
    distance = np.min(np.hypot(*(np.concatenate(walls) - (y, z)).T))
    inside = (y + HALF_CENTRE) ** 2 + z ** 2 < BORE ** 2 or (y - HALF_CENTRE) ** 2 + z ** 2 < BORE ** 2
    return (radius - distance) / radius if inside else (radius + distance) / radius


def test_barrel_overlap_monitor_matches_sampled_wall(tmp_path):
    lines = ["atom_style granular", "atom_modify map array sort 0 0", "boundary p f f", "newton off",
             "units si", "region box block 0 0.02 -0.023 0.023 -0.0135 0.0135 units box",
             "create_box 1 box", f"variable half_centre equal {HALF_CENTRE!r}", "variable barrel_end equal 0.02"]
    for k, (y, z, radius) in enumerate(PARTICLES, start=1):
        lines += [f"create_atoms 1 single 0.01 {float(y)!r} {float(z)!r} units box",
                  f"set atom {k} diameter {2 * float(radius)!r} density 1263"]
    lines += [f"include {ROOT / 'cases' / 'include' / 'barrel_overlap.in'}",
              "dump monitor all custom 1 monitor.txt id v_barrel_overlap_atom", "dump_modify monitor sort id",
              "thermo_style custom step c_barrel_overlap", "run 0"]
    (tmp_path / "in.monitor").write_text("\n".join(lines) + "\n")
    proc = subprocess.run([LMP, "-in", "in.monitor", "-echo", "none"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 0, proc.stdout[-2000:]
    measured = np.loadtxt((tmp_path / "monitor.txt").read_text().splitlines()[9:], ndmin=2)[:, 1]
    expected = np.array([sampled_wall_overlap(*p) for p in PARTICLES])
    np.testing.assert_allclose(measured, expected, atol=2e-3)   # sampling: 0.2 µm on r >= 0.4 mm
    assert expected[5] > 1.0 and expected[0] == pytest.approx(0.4, abs=1e-3) and expected[2] == pytest.approx(0.6, abs=1e-3)


CRAFTED_LOG = """\
    Step           Time    Atoms         KinEng       check_co       check_co       barrel_o        escaped            CPU
       0              0     100              0              0            0.2    -0.1              0              0
     400          0.001     100              1           0.05            0.2     0.3              0              0
Loop time of 1 on 1 procs
    Step           Time    Atoms         KinEng       check_co       check_co       barrel_o        escaped            CPU
     800          0.002      99              1           0.42            0.2     0.25             2              0
WARNING: something interleaved
    1200          0.003      99              1           0.42            0.2     0.61             1              0
"""


def test_log_reading_takes_maxima_losses_and_escapes():
    pair, barrel, filled, fewest, escaped = seed_check.read_run(CRAFTED_LOG)
    assert (pair, barrel, filled, fewest, escaped) == (0.42, 0.61, 100, 99, 2)
    result = seed_check.SeedResult(1, 0, pair, barrel, filled, filled - fewest, escaped, 1.0, "")
    assert result.failures(0.5, 0.7) == ["1 lost", "2 escaped"]
    clean = seed_check.SeedResult(2, 0, pair, barrel, filled, 0, 0, 1.0, "")
    assert clean.failures(0.5, 0.7) == []
    assert clean.failures(0.4, 0.6) == ["pair overlap 0.42 > 0.4", "barrel overlap 0.61 > 0.6"]
    broken = seed_check.SeedResult(3, 1, np.nan, np.nan, 0, 0, 0, 1.0, "lmp failed")
    assert broken.failures(0.5, 0.7) == ["run_case.py exit 1 (lmp failed)", "pair overlap nan > 0.5"]


def test_seed_is_refused_as_pass_through():
    proc = subprocess.run([sys.executable, str(ROOT / "cases" / "seed_check.py"), "--seeds", "1", "--seed", "3"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2 and "--seed is set per seed by seed_check.py" in proc.stderr


def test_two_seeds_of_the_demo_case(tmp_path):
    # 1.5 mm particles: a third of the demo's particle count and fewer sections to cut for the fill
    command = [sys.executable, str(ROOT / "cases" / "seed_check.py"), "--seeds", "3", "7", "--out", str(tmp_path),
               "--scale", "demo", "-v", "d_mean", "0.0015", "-v", "t_startup", "0.001", "-v", "t_sample", "0.0005",
               "-v", "thermo_every", "100", "-v", "stats_every", "100"]
    proc = subprocess.run(command, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert "2 of 2 seeds passed" in proc.stdout
    for seed in (3, 7):
        log = (tmp_path / f"seed-{seed}" / "log.lammps").read_text()
        assert "thermo_every=100" in log                      # -v reached run_case.py
        pair, _barrel, filled, fewest, escaped = seed_check.read_run(log)
        assert filled > 900 and fewest == filled and escaped == 0 and 0.0 <= pair < 0.5
    fills = [(tmp_path / f"seed-{seed}" / "fill.in").read_text() for seed in (3, 7)]
    assert fills[0] != fills[1]                                # the seeds fill differently
