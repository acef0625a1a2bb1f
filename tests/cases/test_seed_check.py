"""cases/seed_check.py: the log reading on a crafted log (maxima of the guards' monitors, losses,
escapes), the pass-through refusal, and a two-seed run of the demo case over a very short window."""
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
from tsg_cases import seed_check

CRAFTED_LOG = """\
    Step           Time    Atoms         KinEng         pp_max       dt_ratio          speed        pg_scr1        pg_scr2         pg_bar        escaped            CPU
       0              0     100              0              0            0.2              0              0              0              0              0              0
     400          0.001     100              1           0.05            0.2            0.8            0.1            0.3           0.05              0              0
Loop time of 1 on 1 procs
    Step           Time    Atoms         KinEng         pp_max       dt_ratio          speed        pg_scr1        pg_scr2         pg_bar        escaped            CPU
     800          0.002      99              1           0.42            0.2            0.9            0.2           0.25            0.1              2              0
WARNING: something interleaved
    1200          0.003      99              1           0.42            0.2            0.7           0.61            0.1            0.2              1              0
"""


def test_log_reading_takes_maxima_losses_and_escapes():
    pair, wall, speed, filled, fewest, escaped = seed_check.read_run(CRAFTED_LOG)
    assert (pair, wall, speed, filled, fewest, escaped) == (0.42, 0.61, 0.9, 100, 99, 2)
    result = seed_check.SeedResult(1, 0, pair, wall, speed, filled, filled - fewest, escaped, 1.0, "")
    assert result.failures(0.5, 0.7) == ["1 lost", "2 escaped"]
    clean = seed_check.SeedResult(2, 0, pair, wall, speed, filled, 0, 0, 1.0, "")
    assert clean.failures(0.5, 0.7) == []
    assert clean.failures(0.4, 0.6, 0.85) == ["pair overlap 0.42 > 0.4", "wall overlap 0.61 > 0.6",
                                              "speed 0.9 m/s > 0.85"]
    broken = seed_check.SeedResult(3, 1, np.nan, np.nan, np.nan, 0, 0, 0, 1.0, "lmp failed")
    assert broken.failures(0.5, 0.7) == ["run_case.py exit 1 (lmp failed)", "pair overlap nan > 0.5"]


def test_feed_case_reports_its_largest_count_and_no_outlet_loss():
    # a feed case starts empty, generates particles and removes them at the outlet: the count that
    # falls from 300 to 280 is not a loss
    log = CRAFTED_LOG.replace("     100  ", "       0  ", 1).replace("     100  ", "     300  ").replace("      99  ", "     280  ")
    pair, wall, speed, filled, fewest, escaped = seed_check.read_run(log)
    assert (filled, fewest) == (300, 300)


def test_seed_is_refused_as_pass_through():
    proc = subprocess.run([sys.executable, "-m", "tsg_cases.seed_check", "--seeds", "1", "--seed", "3"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2 and "--seed is set per seed by seed_check.py" in proc.stderr


def test_two_seeds_of_the_demo_case(tmp_path):
    # 1.5 mm particles: a third of the demo's particle count and fewer sections to cut for the fill
    command = [sys.executable, "-m", "tsg_cases.seed_check", "--seeds", "3", "7", "--out", str(tmp_path),
               "--scale", "demo", "-v", "d_mean", "0.0015", "-v", "t_startup", "0.001", "-v", "t_sample", "0.0005",
               "-v", "thermo_every", "100", "-v", "stats_every", "100"]
    proc = subprocess.run(command, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert "2 of 2 seeds passed" in proc.stdout
    for seed in (3, 7):
        log = (tmp_path / f"seed-{seed}" / "log.lammps").read_text()
        assert "thermo_every=100" in log                      # -v reached run_case.py
        pair, _wall, _speed, filled, fewest, escaped = seed_check.read_run(log)
        assert filled > 900 and fewest == filled and escaped == 0 and 0.0 <= pair < 0.5
    fills = [(tmp_path / f"seed-{seed}" / "fill.in.data").read_text() for seed in (3, 7)]
    assert fills[0] != fills[1]                                # the seeds fill differently


def test_generation_seeds_are_distinct_primes_and_seed_0_is_the_inputs_default():
    # the feed cases' --seed: seed_psd and seed_insert are primes > 10000 (LIGGGHTS' rule), differ
    # between seeds, and seed 0 gives the defaults written in the inputs
    from tsg_cases.run_case import generation_seeds

    def is_prime(n: int) -> bool:
        return n > 1 and all(n % k for k in range(2, int(n ** 0.5) + 1))
    pairs = [generation_seeds(seed) for seed in range(300)]
    values = [v for pair in pairs for v in pair]
    assert all(v > 10000 and is_prime(v) for v in values) and len(set(values)) == len(values)
    for case in ("full", "nonperiodic"):
        text = (ROOT / "cases" / f"in.tsg_{case}").read_text()
        defaults = tuple(int(re.search(rf"variable {name}\s+index (\d+)", text).group(1)) for name in ("seed_psd", "seed_insert"))
        assert generation_seeds(0) == defaults
    assert max(generation_seeds(2_000_000)) < 2**31
