"""The seed paper's sensitivity claims and our directions beside them: a direction counts only when
its difference is significant; 'almost no change' agrees only with a difference that is not."""
import re

import numpy as np
from tsg_analysis.model import AXIAL_VELOCITY, DOMAIN_FLUX, MASS_FLOW, SOLID_FRACTION
from tsg_analysis.summary import ComparisonRow
from tsg_analysis.uncertainty import Difference, Estimate
from tsg_analysis.validation import KNEADING, PAPER_CLAIMS, PAPER_MASS_FLOW, directions, directions_markdown

UNUSED = Estimate(1.0, 0.1, 10, 10.0, 0.2)


def row(variant: str, quantity: str, scope: str, value: float, half_width: float) -> ComparisonRow:
    return ComparisonRow(variant, quantity, scope, UNUSED, UNUSED, Difference(value, half_width, value / 10.0, True))


def verdict(verdicts, variant, quantity, scopes=None):
    return next(v for v in verdicts if v.claim.variant == variant and v.claim.quantity == quantity
                and (scopes is None or v.claim.scopes == scopes))


def test_mass_flow_claims_follow_the_papers_numbers():
    flows = {c.variant: c.direction for c in PAPER_CLAIMS if c.quantity == MASS_FLOW}
    assert flows == {"restitution-0.1": 0, "psd-sigma-0.2": 0, "restitution-0.9": -1, "static-friction-0.1": 1,
                     "rolling-friction-0.2": -1, "cohesion-high": -1}
    assert PAPER_MASS_FLOW["static-friction-0.1"][0] > PAPER_MASS_FLOW["reference"][1]


def test_directions_count_only_significant_differences():
    rows = [row("static-friction-0.1", MASS_FLOW, DOMAIN_FLUX, +3.0, 1.0),            # + significant
            row("cohesion-high", MASS_FLOW, DOMAIN_FLUX, -0.5, 1.0),                  # within its interval
            row("restitution-0.1", MASS_FLOW, DOMAIN_FLUX, +2.0, 1.0),                # paper: no change
            row("psd-sigma-0.2", MASS_FLOW, DOMAIN_FLUX, +0.2, 1.0),                  # paper: no change
            *[row("static-friction-0.1", SOLID_FRACTION, k, -0.01, 0.002) for k in KNEADING[:3]],
            *[row("static-friction-0.1", SOLID_FRACTION, k, -0.001, 0.002) for k in KNEADING[3:]],
            row("static-friction-0.1", AXIAL_VELOCITY, "K1", +0.01, 0.002),
            row("static-friction-0.1", AXIAL_VELOCITY, "K2", -0.01, 0.002)]
    verdicts = directions(rows)
    assert (verdict(verdicts, "static-friction-0.1", MASS_FLOW).agrees, verdict(verdicts, "static-friction-0.1", MASS_FLOW).ours) == ("yes", "+")
    assert verdict(verdicts, "cohesion-high", MASS_FLOW).agrees == "not resolved"
    assert verdict(verdicts, "restitution-0.1", MASS_FLOW).agrees == "no"
    assert verdict(verdicts, "psd-sigma-0.2", MASS_FLOW).agrees == "yes"
    kneading = verdict(verdicts, "static-friction-0.1", SOLID_FRACTION, KNEADING)
    assert (kneading.ours, kneading.agrees) == ("−", "partly") and "K4 -0% (n.s.)" in kneading.detail
    assert verdict(verdicts, "static-friction-0.1", AXIAL_VELOCITY).ours == "mixed"
    assert verdict(verdicts, "rolling-friction-0.2", MASS_FLOW).ours == "no data"
    table = directions_markdown(verdicts)
    assert "| static-friction-0.1 | mass flow domain flux Σ m v_x / L | + | + | yes |" in table


def test_sweep_with_replicas_reports_differences_and_directions(tmp_path):
    """tsg-sweep write --replicas lays out NAME/seed-K runs with their seeds; report combines the
    finished replicas and sets the paper's directions beside ours."""
    import os
    import subprocess
    import sys

    from make_fixture import write_run

    sweep = [sys.executable, "-m", "tsg_cases.sweep"]
    env = dict(os.environ)
    subprocess.run([*sweep, "write", str(tmp_path), "--scale", "demo", "--np", "1", "--replicas", "3",
                    "--only", "reference", "static-friction-0.1", "cohesion-high"], check=True, capture_output=True, env=env)
    names = (tmp_path / "runs.txt").read_text().split()
    assert names == [f"{n}/seed-{k}" for n in ("reference", "static-friction-0.1", "cohesion-high") for k in (1, 2, 3)]
    assert "--seed 2 periodic" in (tmp_path / "cohesion-high" / "seed-2" / "run.sh").read_text()
    rng = np.random.default_rng(5)
    for number, name in enumerate(names):
        run_dir = tmp_path / name
        write_run(run_dir, dumps=None, meshes=False, seed=100 + number)
        # elements.txt rows: index, solid fraction, speed, axial velocity, count, volume. Each replica
        # gets its own noise; static friction 0.1: solid fraction × 0.8, axial velocity × 1.5
        fraction, axial = (0.8, 1.5) if name.startswith("static-friction") else (1.0, 1.0)
        lines = []
        for line in (run_dir / "elements.txt").read_text().splitlines():
            w = line.split()
            if len(w) == 6 and w[0] != "#":
                w[1] = f"{float(w[1]) * fraction * (1 + 0.03 * rng.normal()):.6g}"
                w[3] = f"{float(w[3]) * axial * (1 + 0.03 * rng.normal()):.6g}"
            lines.append(" ".join(w))
        (run_dir / "elements.txt").write_text("\n".join(lines) + "\n")
        if name != "cohesion-high/seed-3":  # a run that has not finished is left out
            (run_dir / "DONE").touch()
    # one run counted 4 squeeze releases (check/contact's thermo column fast, cumulative)
    with open(tmp_path / "static-friction-0.1" / "seed-2" / "log.lammps", "a") as log:
        log.write("Step fast\n0 0\n100 4\nLoop time of 1 on 1 procs for 100 steps\n")
    proc = subprocess.run([*sweep, "report", str(tmp_path)], capture_output=True, text=True, encoding="utf-8", env=env)
    assert proc.returncode == 0, proc.stderr
    assert "reference 3/3, static-friction-0.1 3/3, cohesion-high 2/3" in proc.stdout
    assert "Squeeze releases counted per run (check/contact fast_speed; '-': not counted): reference -, -, -; " \
           "static-friction-0.1 -, 4, -; cohesion-high -, -." in proc.stdout
    assert "| static-friction-0.1 | mass flow domain flux Σ m v_x / L | + | + | yes |" in proc.stdout
    assert "| static-friction-0.1 | axial velocity kneading | + | + | yes |" in proc.stdout
    assert "| static-friction-0.1 | solid fraction kneading | − | − | yes |" in proc.stdout
    # two replicas of an unchanged setting: no number, so no direction
    assert "| cohesion-high | mass flow domain flux Σ m v_x / L | − | window too short | not resolved |" in proc.stdout
    # the flux in each half of the window: static friction's +50 % holds in both halves (the scaled
    # axial velocity is in every sample)
    halves = (tmp_path / "report" / "parts.md").read_text(encoding="utf-8")
    assert re.search(r"\| static-friction-0.1 \| [^|]+ \| \+(4[5-9]|5[0-5])% \| [^|]+ \| \+(4[5-9]|5[0-5])% \|", halves), halves
    for name in ("comparison.md", "comparison.csv", "directions.md", "parts.md", "mass-flow.png", "elements.png"):
        assert (tmp_path / "report" / name).stat().st_size > 0


def test_a_setting_without_enough_replicas_neither_agrees_nor_disagrees():
    short = ComparisonRow("restitution-0.1", MASS_FLOW, DOMAIN_FLUX, UNUSED, UNUSED, Difference(0.1, 1.0, 0.01, False))
    (v,) = [v for v in directions([short]) if v.claim.variant == "restitution-0.1"]
    assert (v.ours, v.agrees) == ("window too short", "not resolved") and "(too short)" in v.detail


def test_report_window_starts_after_the_start_up(tmp_path):
    """A variant whose effect appears only at t = 1.5 s (a start-up of half the record): averaged over
    the whole record its flux is +25 % (half the blocks at +50 %); from --start 1.5 and from the
    detected steady start (--start auto) it is +50 %, and parts.md shows 0 % then +50 %."""
    import os
    import subprocess
    import sys

    from make_fixture import write_run

    sweep = [sys.executable, "-m", "tsg_cases.sweep"]
    env = dict(os.environ)
    subprocess.run([*sweep, "write", str(tmp_path), "--scale", "demo", "--np", "1", "--replicas", "3",
                    "--only", "reference", "static-friction-0.1"], check=True, capture_output=True, env=env)
    rng = np.random.default_rng(11)
    for number, name in enumerate((tmp_path / "runs.txt").read_text().split()):
        run_dir = tmp_path / name
        write_run(run_dir, dumps=None, meshes=False, seed=200 + number)
        lines = []
        for line in (run_dir / "elements.txt").read_text().splitlines():
            w = line.split()
            if len(w) == 2 and not line.startswith("#"):
                late = int(w[0]) * 5.0e-7 > 1.5 + 1e-9   # the block's time (fixture: 5e-7 s per step)
            if len(w) == 6 and w[0] != "#":
                factor = 1.5 if name.startswith("static-friction") and late else 1.0
                w[3] = f"{float(w[3]) * factor * (1 + 0.02 * rng.normal()):.6g}"
            lines.append(" ".join(w))
        (run_dir / "elements.txt").write_text("\n".join(lines) + "\n")
        (run_dir / "DONE").touch()

    def flux_change(*options: str) -> float:
        proc = subprocess.run([*sweep, "report", str(tmp_path), *options], capture_output=True, text=True, encoding="utf-8", env=env)
        assert proc.returncode == 0, proc.stderr
        found = re.search(r"\| static-friction-0.1 \| mass flow domain flux Σ m v_x / L \| [^|]+ \| [^|]+ \| [^|]+ \| "
                          r"domain flux Σ m v_x / L ([+-]\d+)%", proc.stdout)
        assert found, proc.stdout
        return int(found.group(1))

    assert 20 <= flux_change("--parts", "2") <= 30
    parts = (tmp_path / "report" / "parts.md").read_text(encoding="utf-8")
    assert re.search(r"\| static-friction-0.1 \| [^|]+ \| [+-][0-3]% \| [^|]+ \| \+(4[5-9]|5[0-5])% \|", parts), parts
    assert 45 <= flux_change("--start", "1.5") <= 55
    assert 45 <= flux_change("--start", "auto") <= 55
    assert "the latest detected steady start" in (tmp_path / "report" / "parts.md").read_text(encoding="utf-8")
    for bad, why in (("-1", "a time in s >= 0"), ("soon", "a time in s >= 0"), ("5", "too few")):
        proc = subprocess.run([*sweep, "report", str(tmp_path), "--start", bad], capture_output=True, text=True, encoding="utf-8", env=env)
        assert proc.returncode == 2 and why in proc.stderr, proc.stderr


def pair_row(first: str, second: str, quantity: str, scope: str, value: float, half_width: float) -> ComparisonRow:
    return ComparisonRow(f"{first} − {second}", quantity, scope, UNUSED, UNUSED, Difference(value, half_width, value, True))


def test_pair_claims_one_group_only_where_the_interval_is_narrower_than_the_gap():
    """Fig. 14's two groups: μs,pg 0.1 alone beside both at 0.1. An element counts as 'one group' when
    the pair difference is not significant and its interval is narrower than the other group's
    distance (here μs,pg 0.1 from the reference); a significant pair difference is 'no'; an interval
    wider than the gap decides nothing."""
    from tsg_analysis.validation import PAIR_CLAIMS, pair_verdicts
    claims = [c for c in PAIR_CLAIMS if (c.first, c.second, c.quantity) == ("mus_pg-0.1", "static-friction-0.1", SOLID_FRACTION)]
    rows = [row("mus_pg-0.1", SOLID_FRACTION, k, -0.010, 0.002) for k in ("C1", "K1", "K2", "K3", "K4", "K5", "K6", "C2")]
    pairs = [pair_row("mus_pg-0.1", "static-friction-0.1", SOLID_FRACTION, "C1", 0.001, 0.004),   # narrower: one group
             pair_row("mus_pg-0.1", "static-friction-0.1", SOLID_FRACTION, "K1", 0.008, 0.004),   # significant: not
             pair_row("mus_pg-0.1", "static-friction-0.1", SOLID_FRACTION, "K2", 0.001, 0.020)]   # wider than the gap
    (v,) = pair_verdicts(rows, pairs, claims)
    assert (v.ours, v.agrees) == ("holds on 1, contradicted on 1, undecided on 1 of 3", "partly")
    (undecided,) = pair_verdicts(rows, pairs[2:], claims)
    assert (undecided.ours, undecided.agrees) == ("not resolved", "not resolved")


def test_pair_claims_further_needs_the_pair_difference_in_the_direction_of_the_change():
    """Fig. 15: μr,pp 0.2 reduces the axial velocity more than μr,pg 0.2 — pp − pg significantly
    negative where pp's own change is a reduction."""
    from tsg_analysis.validation import PAIR_CLAIMS, pair_verdicts
    claims = [c for c in PAIR_CLAIMS if (c.first, c.second) == ("mur_pp-0.2", "mur_pg-0.2")]
    rows = [row("mur_pp-0.2", AXIAL_VELOCITY, k, -0.02, 0.005) for k in ("C1", "K1", "K2")]
    pairs = [pair_row("mur_pp-0.2", "mur_pg-0.2", AXIAL_VELOCITY, "C1", -0.01, 0.004),   # reduced more: yes
             pair_row("mur_pp-0.2", "mur_pg-0.2", AXIAL_VELOCITY, "K1", +0.01, 0.004),   # reduced less: no
             pair_row("mur_pp-0.2", "mur_pg-0.2", AXIAL_VELOCITY, "K2", -0.001, 0.004)]  # not significant
    (v,) = pair_verdicts(rows, pairs, claims)
    assert (v.ours, v.agrees) == ("holds on 1, contradicted on 1, undecided on 1 of 3", "partly")
    assert pair_verdicts(rows, pairs[:1], claims)[0].agrees == "yes"
    assert pair_verdicts(rows, pairs[1:2], claims)[0].agrees == "no"
