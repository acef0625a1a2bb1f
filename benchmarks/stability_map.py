"""Stability map: for each extreme case of issue 14, the largest stable time step, found on a small
scene that exercises the granulator's contacts, compared with the estimate fix check/contact prints.

    .venv/bin/python benchmarks/stability_map.py [--cases base,stiff,...] [--out DIR]
        [--fractions 0.05,0.1,0.2,0.4,0.8,1.6,3.2] [--bisections 3] [--window 0.02] [--np 1]

Scene (written by this script; particles, materials and contact models from the case includes
cases/include/materials.in and models.in, so every case parameter is a -var of the real cases): a
periodic barrel slice of radius 6 mm and length 6.3 mm, half filled with particles of diameter
${d_mean} on a lattice, and a two-sided paddle through the axis that turns at ${rpm} about it with a
tip clearance of 0.44 mm to the barrel (the ConsiGma-1 flight-tip clearance; docs/geometry.md).
The paddle is driven by fix wall/gran/corotating (Hertz-Mindlin + CDT, as the cases); it shears
the bed, presses particles against the barrel and wedges those larger than the clearance under
its tips, the contacts that fail in the full geometry (shared/reference/measurements.md).

For each case a ladder of time-step fractions f (dt = f x the check/contact estimate), then
bisection (geometric midpoints) between the largest stable and the smallest unstable rung. A run
is unstable when it stops on a kinetic-energy blow-up (a particle faster than 10 x the paddle tip
speed or the fall speed: cases/include/guards.in), a non-finite value, lost atoms, or ends with a
particle outside the barrel. Per run it records the largest particle-particle and
particle-geometry overlap δ/R (check/contact's monitors; overlaps alone do not make a run
unstable: the soft case is meant to show overlaps, not instability).

Writes DIR/stability_map.json (every run), DIR/stability_map.md (the table) and
DIR/stability_map.png (largest stable fraction per case, and the overlaps at f = 0.1); --merge A.json
B.json rebuilds them from earlier runs (B's cases replacing A's). Not a test:
the smoke run tests/cases/test_guards_stability_map.py runs it on a tiny scene.
"""
from __future__ import annotations

import argparse
import json
import math
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from tsg_analysis.liggghts_log import parse_thermo
from tsg_cases.launcher import lmp_executable, mpi_command

ROOT = Path(__file__).resolve().parents[1]

BARREL_RADIUS = 0.006   # m
SLICE_LENGTH = 0.0063   # m, periodic along x (6 lattice layers of 1 mm particles)
CLEARANCE = 0.00044     # m, paddle tip to barrel (ConsiGma-1 flight tip clearance)
SEGMENTS = 48           # barrel facets around the circumference

# the extreme cases of issue 14 item 1, as -var overrides of the case parameters
CASES: dict[str, dict[str, object]] = {
    "base": {},
    "stiff": {"G_p": 1.7e9, "G_g": 1.0e10},                    # G x 100
    "soft": {"G_p": 1.7e5, "G_g": 1.0e6},                      # G / 100
    "lambda-0.99": {"cohesion": 1, "lambda_p": 0.99},
    "cohesion-x10": {"cohesion": 1, "dgamma": 150.0, "f0": -0.01},  # Δγ x 10, f0 x 10
    "elastic-0.99": {"e_pp": 0.99, "e_pg": 0.99},
    "friction-1.0": {"mus_pp": 1.0, "mus_pg": 1.0, "mur_pp": 0.5, "mur_pg": 0.5},
    "rpm-1200": {"rpm": 1200},
    "coarse-1.5mm": {"d_mean": 0.0015, "mus_pg": 0.5},
    "holdup-x2": {"fill_top": 1.0},                            # whole barrel instead of half
    "size-ratio-3": {"size_ratio": 3},
}
DEFAULTS: dict[str, object] = {"d_mean": 0.001, "rpm": 600, "cohesion": 0, "fill_top": 0.0, "size_ratio": 1}

SCENE = """# stability-map scene (benchmarks/stability_map.py)
variable case_dir index {case_dir}
atom_style    granular
atom_modify   map array
boundary      p f f
newton        off
communicate   single vel yes
units         si
hard_particles yes                  # the stiff and soft cases' moduli are outside LIGGGHTS'
soft_particles yes                  # SI sanity limits (5e6 <= E <= 1e9 Pa)
region        box block 0 {length!r} -{box!r} {box!r} -{box!r} {box!r} units box
create_box    2 box
variable      skin index $(0.2*v_d_mean)   # neighbour skin, m (models.in sets neighbor)
include ${{case_dir}}/include/materials.in
include ${{case_dir}}/include/models.in
fix barrel all mesh/surface file barrel.stl type 2
fix paddle all mesh/surface file paddle.stl type 2
variable period equal 60.0/${{rpm}}
fix walls all wall/gran/corotating model hertz tangential history rolling_friction cdt &
    mesh n_meshes 2 meshes paddle barrel &
    corotate paddle origin 0 0 0 axis 1 0 0 period ${{period}} fixed barrel
# fill: a lattice in the barrel below z = fill_top x radius, clear of the paddle (the x-z plane)
variable d_large equal ${{d_mean}}
variable d_small equal ${{d_mean}}/${{size_ratio}}
variable inner equal {radius!r}-0.6*v_d_large
region inside cylinder x 0 0 ${{inner}} INF INF units box
region below block INF INF INF INF INF $(v_fill_top*{radius!r}-0.6*v_d_large) units box
region blade block INF INF $(-0.6*v_d_large) $(0.6*v_d_large) INF INF units box side out
region fill intersect 3 inside below blade
lattice sc {spacing!r}
create_atoms 1 region fill
set group all diameter ${{d_large}} density ${{rho_p}}
variable odd atom id%2
group small variable odd
if "${{size_ratio}} != 1" then "set group small diameter ${{d_small}} density ${{rho_p}}"
variable d_min equal ${{d_small}}
fix integrate all nve/sphere
fix gravity all gravity 9.81 vector 0 0 -1
variable rayleigh equal PI*0.5*${{d_min}}*sqrt(${{rho_p}}/${{G_p}})/(0.1631*${{nu_p}}+0.8766)
variable eepa_factor equal (${{cohesion}}==1)*sqrt(1-${{lambda_p}})+(${{cohesion}}==0)
timestep $({fraction!r}*v_rayleigh*v_eepa_factor)
# guards as cases/include/guards.in, overlaps monitored but not stopping the run
variable tip_speed equal 2*PI*{radius!r}*abs(${{rpm}})/60
variable fall_speed equal sqrt(2*9.81*{diameter!r})
variable max_speed equal 10*(v_tip_speed*(v_tip_speed>=v_fall_speed)+v_fall_speed*(v_tip_speed<v_fall_speed))
fix check_contact all check/contact every {every} step_fraction 1 action warn max_speed ${{max_speed}} walls walls
region bore cylinder x 0 0 {radius!r} INF INF units box
variable escaped equal count(all)-count(all,bore)
variable pp equal f_check_contact[2]
variable speed equal f_check_contact[5]
variable paddle equal f_check_contact[6]
variable barrel equal f_check_contact[7]
thermo_style custom step atoms ke v_pp v_speed v_paddle v_barrel v_escaped
thermo_modify norm no lost error format float %.10g
thermo {every}
run $({every}*ceil({window!r}/dt/{every}))
print "MAP-DONE escaped ${{escaped}}"
"""


def barrel_stl() -> str:
    """Cylinder r = BARREL_RADIUS about x, 0 <= x <= SLICE_LENGTH, normals inward (unused by LIGGGHTS)."""
    angles = np.linspace(0, 2 * np.pi, SEGMENTS + 1)
    y, z = BARREL_RADIUS * np.cos(angles), BARREL_RADIUS * np.sin(angles)
    facets = []
    for k in range(SEGMENTS):
        a0, a1 = (0.0, y[k], z[k]), (0.0, y[k + 1], z[k + 1])
        b0, b1 = (SLICE_LENGTH, y[k], z[k]), (SLICE_LENGTH, y[k + 1], z[k + 1])
        facets += [(a0, b0, b1), (a0, b1, a1)]
    return stl("barrel", facets)


def paddle_stl() -> str:
    """Flat two-sided paddle in the x-z plane through the axis, tips CLEARANCE from the barrel."""
    tip = BARREL_RADIUS - CLEARANCE
    corners = [(0.0, 0.0, -tip), (SLICE_LENGTH, 0.0, -tip), (SLICE_LENGTH, 0.0, tip), (0.0, 0.0, tip)]
    return stl("paddle", [(corners[0], corners[1], corners[2]), (corners[0], corners[2], corners[3])])


def stl(name: str, facets: list) -> str:
    body = "".join("facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in f)
                   + "endloop\nendfacet\n" for f in facets)
    return f"solid {name}\n{body}endsolid {name}\n"


@dataclass
class Run:
    case: str
    fraction: float
    stable: bool
    reason: str                    # "" when stable
    timestep: float = math.nan     # s
    estimate: float = math.nan     # s, printed by check/contact
    steps: int = 0
    particles: int = 0
    max_pair_overlap: float = math.nan   # δ/R
    max_wall_overlap: dict = field(default_factory=dict)  # mesh -> δ/R
    max_speed: float = math.nan    # m/s
    seconds: float = 0.0


def run_scene(case: str, fraction: float, window: float, workdir: Path, nprocs: int = 1, every: int = 100) -> Run:
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / "barrel.stl").write_text(barrel_stl())
    (workdir / "paddle.stl").write_text(paddle_stl())
    variables = dict(DEFAULTS, **CASES[case])
    d_mean = float(variables["d_mean"])
    (workdir / "in.scene").write_text(SCENE.format(
        case_dir=ROOT / "cases", length=SLICE_LENGTH, box=BARREL_RADIUS + 0.001, radius=BARREL_RADIUS,
        fraction=fraction, diameter=2 * BARREL_RADIUS, every=every, window=window,
        # lattice spacing about 1.05 d that fits the periodic length a whole number of times
        spacing=SLICE_LENGTH / math.floor(SLICE_LENGTH / (1.05 * d_mean))))
    command = [lmp_executable(), "-in", "in.scene", "-log", "log.lammps", "-echo", "none"]
    for name, value in variables.items():
        command += ["-var", name, str(value)]
    if nprocs > 1:
        command = mpi_command(nprocs) + command
    start = time.perf_counter()
    proc = subprocess.run(command, cwd=workdir, capture_output=True, text=True, errors="replace")
    seconds = time.perf_counter() - start
    log_path = workdir / "log.lammps"
    log = log_path.read_text(errors="replace") if log_path.exists() else proc.stdout
    run = Run(case=case, fraction=fraction, stable=False, reason="", seconds=seconds)
    estimate = re.search(r"critical step estimate (\S+) s .*?time step (\S+) s", log)
    if estimate:
        run.estimate, run.timestep = float(estimate.group(1)), float(estimate.group(2))
    thermo = parse_thermo(log)
    if thermo:
        rows = {key: np.concatenate([t[key] for t in thermo if key in t]) for key in thermo[0]}
        run.steps = int(rows["Step"][-1])
        run.particles = int(rows["Atoms"][0])
        run.max_pair_overlap = float(np.nanmax(rows["pp"]))
        run.max_speed = float(np.nanmax(rows["speed"]))
        run.max_wall_overlap = {"paddle": float(np.nanmax(rows["paddle"])), "barrel": float(np.nanmax(rows["barrel"]))}
    errors = [line for line in (log + proc.stdout).splitlines() if line.startswith("ERROR")]
    done = re.search(r"MAP-DONE escaped (\d+)", log)
    if proc.returncode != 0 or not done:
        message = errors[0] if errors else f"exit {proc.returncode}"
        if "moves at" in message:
            run.reason = "kinetic-energy blow-up"
        elif "non-finite" in message:
            run.reason = "NaN"
        elif "Lost atoms" in message:
            run.reason = "lost atoms"
        else:
            raise RuntimeError(f"{case} at f = {fraction}: lmp failed for a reason that is not instability: {message}"
                               f" (in {workdir})")
        # the step at which it stopped, from the guard's message
        stopped = re.search(r"step (\d+)", message)
        if stopped:
            run.steps = int(stopped.group(1))
    elif int(done.group(1)) > 0:
        run.reason = f"{done.group(1)} particles escaped the barrel"
    else:
        run.stable = True
    return run


def largest_stable(stable_at, fractions: list[float], bisections: int) -> tuple[float, float]:
    """Largest stable fraction on the ladder, refined by bisection (geometric midpoints) towards the
    smallest unstable rung above it: (largest stable, smallest unstable) found; nan when none."""
    results = {f: stable_at(f) for f in sorted(fractions)}
    stable = [f for f, ok in results.items() if ok]
    if not stable:
        return math.nan, min(fractions)
    low = max(stable)
    above = [f for f, ok in results.items() if not ok and f > low]
    if not above:
        return low, math.nan
    high = min(above)
    for _ in range(bisections):
        middle = math.sqrt(low * high)
        if stable_at(middle):
            low = middle
        else:
            high = middle
    return low, high


def map_case(case: str, fractions: list[float], bisections: int, window: float, out: Path, nprocs: int,
             runs: list[Run]) -> dict:
    def stable_at(fraction: float) -> bool:
        run = run_scene(case, fraction, window, out / case / f"f{fraction:.5g}", nprocs)
        runs.append(run)
        print(f"  {case:14s} f = {fraction:<8.4g} {'stable' if run.stable else 'UNSTABLE: ' + run.reason:32s} "
              f"pp {run.max_pair_overlap:.3g}  pg {max(run.max_wall_overlap.values(), default=math.nan):.3g}  "
              f"({run.seconds:.0f} s)", flush=True)
        return run.stable
    low, high = largest_stable(stable_at, fractions, bisections)
    return {"case": case, "largest_stable_fraction": low, "smallest_unstable_fraction": high,
            # half the largest stable step, at most the 20 % the guards allow
            "safe_fraction": min(0.2, low / 2) if math.isfinite(low) else math.nan}


def table(summary: list[dict], runs: list[Run], reference: float) -> str:
    lines = ["| case | largest stable f | smallest unstable f | safe f | at f = "
             f"{reference:g}: pp δ/R | pg δ/R (paddle, barrel) | estimate (s) |",
             "|---|---|---|---|---|---|---|"]
    for s in summary:
        at = [r for r in runs if r.case == s["case"] and math.isclose(r.fraction, reference)]
        r = at[0] if at else None
        lines.append(f"| {s['case']} | {s['largest_stable_fraction']:.3g} | {s['smallest_unstable_fraction']:.3g} | "
                     f"{s['safe_fraction']:.3g} | "
                     + (f"{r.max_pair_overlap:.3g} | {r.max_wall_overlap.get('paddle', math.nan):.3g}, "
                        f"{r.max_wall_overlap.get('barrel', math.nan):.3g} | {r.estimate:.3g} |" if r else "– | – | – |"))
    return "\n".join(lines) + "\n"


def figure(summary: list[dict], runs: list[Run], reference: float, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = [s["case"] for s in summary]
    x = np.arange(len(names))
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
    top.bar(x, [s["largest_stable_fraction"] for s in summary], color="tab:green", label="largest stable")
    top.scatter(x, [s["smallest_unstable_fraction"] for s in summary], color="tab:red", marker="v",
                label="smallest unstable", zorder=3)
    top.axhline(0.2, color="k", lw=0.8, ls="--", label="guard: 0.2")
    top.set_yscale("log")
    top.set_ylabel("dt / check/contact estimate")
    top.legend(fontsize=8)
    pp, paddle, barrel = [], [], []
    for name in names:
        at = [r for r in runs if r.case == name and math.isclose(r.fraction, reference)]
        pp.append(at[0].max_pair_overlap if at else math.nan)
        paddle.append(at[0].max_wall_overlap.get("paddle", math.nan) if at else math.nan)
        barrel.append(at[0].max_wall_overlap.get("barrel", math.nan) if at else math.nan)
    bottom.bar(x - 0.25, pp, 0.25, label="particle-particle")
    bottom.bar(x, paddle, 0.25, label="paddle")
    bottom.bar(x + 0.25, barrel, 0.25, label="barrel")
    bottom.axhline(0.5, color="k", lw=0.8, ls="--", label="guard: 0.5")
    bottom.set_ylabel(f"largest δ/R at f = {reference:g}")
    bottom.set_xticks(x, names, rotation=30, ha="right")
    bottom.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def merge(paths: list[Path], out: Path) -> int:
    summary: dict[str, dict] = {}
    runs: dict[str, list[Run]] = {}
    fractions: set[float] = set()
    for path in paths:
        data = json.loads(path.read_text())
        fractions |= set(data["fractions"])
        for entry in data["summary"]:
            summary[entry["case"]] = entry
            runs[entry["case"]] = [Run(**r) for r in data["runs"] if r["case"] == entry["case"]]
    ordered = [summary[c] for c in CASES if c in summary]
    all_runs = [r for c in CASES if c in runs for r in runs[c]]
    reference = 0.1 if 0.1 in fractions else min(fractions)
    out.mkdir(parents=True, exist_ok=True)
    (out / "stability_map.json").write_text(json.dumps(
        {"merged_from": [str(p) for p in paths], "summary": ordered, "runs": [asdict(r) for r in all_runs]}, indent=1))
    text = table(ordered, all_runs, reference)
    (out / "stability_map.md").write_text(text)
    figure(ordered, all_runs, reference, out / "stability_map.png")
    print(text)
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated, from: " + ", ".join(CASES))
    parser.add_argument("--fractions", default="0.05,0.1,0.2,0.4,0.8,1.6,3.2")
    parser.add_argument("--bisections", type=int, default=3)
    parser.add_argument("--window", type=float, default=0.02, help="simulated time per run, s")
    parser.add_argument("--np", type=int, default=1)
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--merge", type=Path, nargs="+", default=None, metavar="JSON",
                        help="no runs: merge earlier results (a case in a later file replaces it in an earlier "
                             "one) into --out's JSON, table and figure")
    args = parser.parse_args(argv)
    if args.merge:
        return merge(args.merge, args.out or Path("."))
    cases = args.cases.split(",")
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        parser.error(f"--cases: unknown {', '.join(unknown)} (allowed: {', '.join(CASES)})")
    fractions = [float(f) for f in args.fractions.split(",")]
    if any(not (f > 0) for f in fractions):
        parser.error(f"--fractions = {args.fractions}: every fraction must be > 0")
    out = args.out or Path(tempfile.mkdtemp(prefix="stability_map_"))
    out.mkdir(parents=True, exist_ok=True)
    reference = 0.1 if 0.1 in fractions else min(fractions)
    runs: list[Run] = []
    summary = []
    for case in cases:
        try:
            summary.append(map_case(case, fractions, args.bisections, args.window, out, args.np, runs))
        except RuntimeError as failure:   # not instability: report it and go on with the other cases
            print(f"  {case}: {failure}", flush=True)
            summary.append({"case": case, "largest_stable_fraction": math.nan, "smallest_unstable_fraction": math.nan,
                            "safe_fraction": math.nan, "error": str(failure)})
        (out / "stability_map.json").write_text(json.dumps(
            {"window_s": args.window, "fractions": fractions, "bisections": args.bisections,
             "summary": summary, "runs": [asdict(r) for r in runs]}, indent=1))
    text = table(summary, runs, reference)
    (out / "stability_map.md").write_text(text)
    figure(summary, runs, reference, out / "stability_map.png")
    print(text)
    print(f"written: {out}/stability_map.json, stability_map.md, stability_map.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
