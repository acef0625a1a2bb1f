"""Bad input to fix residence/time, compute element/stats and fix massflow/planes: a clear error that
names the file, line, keyword or value and what is allowed."""
import pytest

from measure_cases import BASE, particles_include, Mover, variables, zones_text
from tsg_harness import run_lmp

GOOD_ZONES = zones_text()
ZONE_FILES = {
    "good.txt": GOOD_ZONES,
    "short.txt": "# header\n1 conveying 0.01 0.03 2e-6\n2 kneading 0.03 0.04\n",
    "type.txt": "1 conveying 0.01 0.03 2e-6\n2 mixing 0.03 0.04 1e-6\n",
    "overlap.txt": "1 conveying 0.01 0.03 2e-6\n2 kneading 0.025 0.04 1e-6\n",
    "unsorted.txt": "1 conveying 0.03 0.04 2e-6\n2 kneading 0.01 0.02 1e-6\n",
    "outside.txt": "1 conveying 0.01 0.03 2e-6\n2 kneading 0.09 0.12 1e-6\n",
    "number.txt": "1 conveying 0.01 0.03mm 2e-6\n",
    "empty.txt": "# nothing here\n",
}


def text(command: str, after: str = "run 10\n") -> str:
    return (BASE + "include particles.include\nfix integr all nve/sphere\n" + command + "\n"
            "timestep 1e-4\n" + after)


def run_bad(tmp_path, command, periodic=False, after="run 10\n"):
    files = dict(ZONE_FILES)
    files["particles.include"] = particles_include([Mover(0.02, 0.1, 0.0, 0.0), Mover(0.05, 0.1, 0.005, 0.0)])
    run = run_lmp(text(command, after), tmp_path, variables=variables(periodic), files=files, expect_error=True)
    return " ".join(run.errors)


RT = "fix rt all residence/time records r.txt zones "

CASES = {
    # zones file problems (the same parser serves the fix and the compute)
    "missing-file": (RT + "nope.txt", False, ["zones file 'nope.txt'", "missing or not readable"]),
    "short-line": (RT + "short.txt", False, ["short.txt", "line 3", "expected 5 fields", "found 4"]),
    "bad-type": (RT + "type.txt", False, ["line 2", "type 'mixing'", "conveying, kneading, chopping"]),
    "overlap": (RT + "overlap.txt", False, ["line 2", "overlaps zone 1 (line 1)"]),
    "unsorted": (RT + "unsorted.txt", False, ["line 2", "must be sorted by x_start"]),
    "bad-number": (RT + "number.txt", False, ["line 1", "x_end '0.03mm'", "not a finite number"]),
    "no-zones": (RT + "empty.txt", False, ["empty.txt", "no zones"]),
    "zone-outside-box": (RT + "outside.txt", False,
                         ["line 2", "zone 2 [0.09, 0.12]", "outside the simulation box along x [0, 0.1]"]),
    # planes and keywords
    "inlet-outside": (RT + "good.txt inlet 0.2", False, ["inlet plane x = 0.2", "outside the simulation box"]),
    "outlet-outside": (RT + "good.txt outlet -0.01", False, ["outlet plane x = -0.01", "outside the simulation box"]),
    "reference-at-hi": (RT + "good.txt periodic 0.1", True, ["periodic reference plane x = 0.1", "[0, 0.1)"]),
    "outlet-before-inlet": (RT + "good.txt inlet 0.05 outlet 0.04", False,
                            ["outlet 0.04 must lie downstream (+x) of inlet 0.05"]),
    "periodic-needs-periodic-box": (RT + "good.txt periodic 0.0", False, ["'periodic' needs a box periodic in x"]),
    "periodic-box-needs-keyword": (RT + "good.txt outlet 0.09", True, ["box is periodic in x", "periodic X"]),
    "periodic-and-outlet": (RT + "good.txt periodic 0.0 outlet 0.09", True,
                            ["'periodic' cannot be combined with 'inlet' or 'outlet'"]),
    "analysis-reversed": (RT + "good.txt analysis 0.09 0.01", False, ["analysis XLO XHI = 0.09 0.01", "XLO < XHI"]),
    "analysis-outside": (RT + "good.txt analysis -0.05 0.09", False, ["analysis XLO plane x = -0.05"]),
    "not-a-number": (RT + "good.txt inlet 5cm", False, ["inlet value '5cm' is not a finite number"]),
    "existing-value": (RT + "good.txt existing maybe", False, ["existing = 'maybe'", "'tag' or 'wait'"]),
    "flush-zero": (RT + "good.txt flush 0", False, ["flush = '0'", "positive integer"]),
    "unknown-keyword": (RT + "good.txt speed 3", False, ["unknown keyword 'speed'", "allowed: zones, records"]),
    "missing-records": ("fix rt all residence/time zones good.txt", False, ["missing 'records FILE'"]),
    "keyword-without-value": (RT + "good.txt inlet", False, ["keyword 'inlet' needs 1 value(s)"]),
    # compute element/stats
    "compute-missing-file": ("compute es all element/stats zones nope.txt", False,
                             ["compute es element/stats", "zones file 'nope.txt'"]),
    "compute-outside-box": ("compute es all element/stats zones outside.txt\nthermo_style custom step c_es[1][1]",
                            False, ["compute es element/stats", "zone 2 [0.09, 0.12]", "outside the simulation box"]),
    "compute-syntax": ("compute es all element/stats good.txt", False,
                       ["expected 'compute ID group element/stats zones ZONES_FILE'"]),
    # fix massflow/planes
    "sensor-outside": ("fix mf all massflow/planes planes 2 0.05 0.15 window 100", False,
                       ["plane 2 at x = 0.15", "outside the simulation box along x [0, 0.1]"]),
    "sensor-at-periodic-hi": ("fix mf all massflow/planes planes 1 0.1 window 100", True, ["plane 1 at x = 0.1", "[0, 0.1)"]),
    "sensor-count": ("fix mf all massflow/planes planes 3 0.05 0.06 window 100", False,
                     ["plane 3 position 'window' is not a finite number", "'planes 3' needs 3 positions"]),
    "sensor-no-window": ("fix mf all massflow/planes planes 1 0.05", False, ["missing 'window N'"]),
    "sensor-window-zero": ("fix mf all massflow/planes planes 1 0.05 window 0", False,
                           ["window = '0' must be a positive number of steps"]),
    "sensor-bad-count": ("fix mf all massflow/planes planes two 0.05 window 10", False,
                         ["sensor count K between 1 and 1000, got 'two'"]),
}


@pytest.mark.parametrize("case", CASES)
def test_bad_input_is_a_clear_error(tmp_path, case):
    command, periodic, expected = CASES[case]
    message = run_bad(tmp_path, command, periodic)
    for part in expected:
        assert part in message, f"'{part}' not in: {message}"


def test_renumbered_ids_are_refused(tmp_path):
    # delete_atoms ... compress yes renumbers the survivors: records would name the wrong particles
    message = run_bad(tmp_path, RT + "good.txt outlet 0.09",
                      after="run 10\nregion first block 0.01 0.03 -0.01 0.01 -0.01 0.01 units box\n"
                            "delete_atoms region first compress yes\nrun 10\n")
    assert "particle id changed from 2 to 1" in message and "compress no" in message, message
