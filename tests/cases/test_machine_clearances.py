"""The runner's machine per scale: the demo's clearances follow the largest particle (1.2 x, rounded
up to 0.1 mm); the paper scale keeps the paper's machine; --clearances names the gaps."""
import pytest
from tsg_cases.psd import size_classes
from tsg_cases.run_case import PSD_CLASSES, SCALES, machine_clearances

DEMO = SCALES["demo"]["gap_factor"]


def test_demo_gaps_are_the_largest_particle_times_1_2_rounded_up_to_a_tenth_of_a_millimetre():
    largest = float(size_classes(0.05, PSD_CLASSES)[0].max())        # relative to the mean diameter
    assert 1.15 < largest < 1.17                                       # docs/geometry.md: 1.16 mm at 1 mm
    assert machine_clearances(DEMO, 1e-3, 0.05) == pytest.approx((1.4e-3, 2.8e-3, 1.4e-3), abs=1e-12)   # 1.39 -> 1.4
    assert machine_clearances(DEMO, 1.5e-3, 0.05) == pytest.approx((2.1e-3, 4.2e-3, 2.1e-3), abs=1e-12)  # 2.08 -> 2.1


    assert machine_clearances(None, 4e-4, 0.05) == (None, None, 0.0)


def test_clearances_build_that_machine_and_are_recorded(tmp_path):
    """Run a few steps on a machine given by --clearances: params.json and the machine file name the gaps,
    and the screws' outer and root radii follow from the bore radius and the centre distance."""
    import json
    import subprocess
    import sys
    out = tmp_path / "run"
    proc = subprocess.run([sys.executable, "-m", "tsg_cases.run_case", "periodic", "--scale", "demo", "--out", str(out),
                           "--clearances", "1.2e-3", "2.8e-3", "1.4e-3", "--holdup-g", "0.3",
                           "-v", "t_startup", "1e-5", "-v", "t_sample", "1e-5"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    params = json.loads((out / "params.json").read_text())
    assert params["clearances_m"] == {"tip_to_barrel": 1.2e-3, "screw_to_screw": 2.8e-3, "disc_spacer": 1.4e-3}
    machine = dict(line.split()[1::2] for line in (out / "machine.in").read_text().splitlines()
                   if line.startswith("variable"))
    assert float(machine["barrel_clearance"]) == pytest.approx(1.2e-3, abs=1e-12)
    assert float(machine["disc_gap"]) == pytest.approx(1.4e-3, abs=1e-12)
    outer = float(machine["screw_outer_radius"])
    assert outer == pytest.approx(12.5e-3 - 1.2e-3, abs=1e-9)                                   # bore radius 12.5 mm
    assert float(machine["screw_root_radius"]) == pytest.approx(19.31e-3 - outer - 2.8e-3, abs=1e-9)  # centre distance 19.31 mm
