"""Stability map: for each extreme case of issue 14 and each tip clearance of issue 33, the largest
stable time step, found on a small scene that exercises the granulator's contacts, compared with the
estimate fix check/contact prints, with the squeeze ledger of every run.

    .venv/bin/python benchmarks/stability_map.py [--cases base,stiff,...] [--out DIR]
        [--fractions 0.05,0.1,0.2,0.4,0.8,1.6,3.2] [--bisections 3] [--floor 0.0125] [--window 0.02] [--np 1]

Scene (written by this script; particles, materials and contact models from the case includes
cases/include/materials.in and models.in, so every case parameter is a -var of the real cases): a
periodic barrel slice of radius 6 mm and length 6.3 mm, its lower half filled with particles of
diameter ${d_mean} on a lattice (each site moved at random by up to 0.02 d, seeded), and a paddle that
turns at ${rpm} about the axis: a kneading disc of the paper's two-flight self-wiping profile
(tsg_meshes.profile.ScrewProfile; root radius 6.90 mm scaled to this barrel, 3.31 mm), its tips
`clearance` from the barrel (per case; 0.44 mm, the ConsiGma-1 flight-tip clearance, unless the case
says otherwise: docs/geometry.md). Its flanks close on the barrel towards each tip, so a particle
wider than the clearance is drawn into a narrowing gap and squeezed, as between the paper's screws
and barrel. The paddle is a closed prism (normals outward: a particle centre inside it is a wall
crossing) driven by fix wall/gran/corotating (Hertz-Mindlin + CDT, as the cases).

Every run has the guards and the squeeze ledger of the real cases, decided as there from the gap
(cases/include/guards.in, the paddle's tip clearance standing for the machine's gaps): a case whose
clearance is narrower than its smallest particle is a squeeze case, where squeezes are the model:
the overlap and speed guards are off and fast particles are counted (fast_speed); in a passing case
(clearance >= smallest particle) they stop the run (overlap 0.5 of the radius, the speed a contact at
that overlap can give). fix squeeze/ledger (cases/include/squeeze_ledger.in) counts squeezes and
stops an energy runaway (guard_max_energy_excess 0.05) in both.

For each case a ladder of time-step fractions f (dt = f x the check/contact estimate), then
bisection (geometric midpoints) between the largest stable rung below the smallest unstable one and
that one; when the smallest rung is unstable, halved rungs down to --floor first. A run is unstable
when it stops on an energy runaway (the particles' kinetic energy above what the paddle and gravity
brought), a non-finite value, lost atoms, in a passing case the overlap or speed guard, or ends with
a particle outside the barrel. Wall crossings (a particle centre behind the paddle's or the barrel's
surface) are counted and the first three named per run, as the real cases do (guard_max_crossed -1):
not fatal by themselves; a centre pushed through the barrel leaves the box (lost atoms) or ends
outside it (escaped), which are. Per run it records the largest particle-particle and
particle-geometry overlap δ/R (check/contact's monitors), the fast_speed events, and the ledger
(ledger_of): events (closed squeezes, δ/R > 0.1 against a wall or a particle), squeezes still open
at the end, squeezes begun per simulated second, the deepest wall and pair δ/R and the largest
release speed of the closed events, crossings and the largest energy excess.

Writes DIR/stability_map.json (every run), DIR/stability_map.md (the tables) and
DIR/stability_map.png (largest stable fraction per case, the overlaps and ledger events at f = 0.1);
--merge A.json B.json rebuilds them from earlier runs (B's cases replacing A's). Not a test:
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
from tsg_meshes.profile import BORE_RADIUS, ScrewProfile

ROOT = Path(__file__).resolve().parents[1]

BARREL_RADIUS = 0.006      # m
SLICE_LENGTH = 0.0063      # m, periodic along x (6 lattice layers of 1 mm particles)
CLEARANCE = 0.00044        # m, paddle tip to barrel unless a case sets `clearance` (ConsiGma-1 flight tip clearance)
ROOT_RADIUS = 6.90e-3 * BARREL_RADIUS / BORE_RADIUS   # m, the ConsiGma-1 kneading disc scaled to this barrel
SEGMENTS = 180             # barrel facets around the circumference (chord sag 0.9 um)
PADDLE_STEP_DEG = 1.0      # the paddle profile sampled about every 1 deg and at its arcs' ends (chord sag < 0.3 um)
PADDLE_ROWS = 8            # the paddle's facets split along x (LIGGGHTS refuses triangles with an angle < 0.26 deg)
JITTER, JITTER_SEED = 0.02, 1  # fill sites moved by up to ±0.02 d (the lattice's gaps are 0.05 d); --seed
PAPER_RATIO = 0.175 / 0.6  # the paper's machine: 0.175 mm between the screws, particles up to 0.6 mm

# the extreme cases of issue 14 item 1, as -var overrides of the case parameters, and the tip
# clearances of issue 33 item 4 (`clearance`, m: a parameter of the scene, not a -var)
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
    # clearance / largest particle: 1.2 passes (the demo rule), below 1 squeezes; base is 0.44
    "gap-1.2": {"clearance": 1.2e-3},
    "gap-0.8": {"clearance": 0.8e-3},
    "gap-0.5": {"clearance": 0.5e-3},
    "gap-0.29": {"clearance": PAPER_RATIO * 1e-3},             # the paper's ratio, 0.175 / 0.6
    "paper-400um": {"d_mean": 0.0004, "clearance": 0.000175},  # the paper's particles and gap
}
DEFAULTS: dict[str, object] = {"d_mean": 0.001, "rpm": 600, "cohesion": 0, "fill_top": 0.0, "size_ratio": 1}
SCENE_PARAMETERS = ("clearance",)   # geometry written by this script, not passed to lmp


@dataclass(frozen=True)
class Geometry:
    clearance: float   # m
    d_min: float       # m, smallest particle
    d_max: float       # m, largest particle

    @property
    def ratio(self) -> float:
        """Clearance / largest particle (the demo rule passes at >= 1.2)."""
        return self.clearance / self.d_max

    @property
    def squeeze(self) -> bool:
        """Narrower than the smallest particle: every particle that enters it is squeezed (guards.in's rule)."""
        return self.clearance < self.d_min


def geometry(case: str) -> Geometry:
    variables = dict(DEFAULTS, **CASES[case])
    d_mean, size_ratio = float(variables["d_mean"]), float(variables["size_ratio"])   # type: ignore[arg-type]
    clearance = float(variables.get("clearance", CLEARANCE))   # type: ignore[arg-type]
    return Geometry(clearance=clearance, d_min=d_mean / size_ratio, d_max=d_mean)


SCENE = """# stability-map scene (benchmarks/stability_map.py)
variable case_dir index {case_dir}
variable out_dir index .
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
# fill: lattice sites in the barrel below z = fill_top x radius, clear of the paddle (fill.in, written
# by benchmarks/stability_map.py)
include fill.in
variable d_large equal ${{d_mean}}
variable d_small equal ${{d_mean}}/${{size_ratio}}
set group all diameter ${{d_large}} density ${{rho_p}}
variable odd atom id%2
group small variable odd
if "${{size_ratio}} != 1" then "set group small diameter ${{d_small}} density ${{rho_p}}"
variable d_min equal ${{d_small}}
fix integrate all nve/sphere
variable gravity index 9.81
fix gravity all gravity ${{gravity}} vector 0 0 -1
variable rayleigh equal PI*0.5*${{d_min}}*sqrt(${{rho_p}}/${{G_p}})/(0.1631*${{nu_p}}+0.8766)
variable eepa_factor equal (${{cohesion}}==1)*sqrt(1-${{lambda_p}})+(${{cohesion}}==0)
timestep $({fraction!r}*v_rayleigh*v_eepa_factor)
# the guards of the cases (cases/include/guards.in), which decide from the gap: the paddle's tip
# clearance is the machine's only gap ({mode})
variable screw_clearance index 1
variable disc_gap index {clearance!r}
include ${{case_dir}}/include/guards.in
variable speed_key string ""
variable speed_value string ""
variable pair_key string ""
variable pair_value string ""
variable wall_key string ""
variable wall_value string ""
if "${{guard_max_speed}} > 0" then &
    "variable speed_key string max_speed" "variable speed_value string ${{guard_max_speed}}"
if "${{guard_max_pair_overlap}} > 0" then &
    "variable pair_key string max_pair_overlap" "variable pair_value string ${{guard_max_pair_overlap}}"
if "${{guard_max_wall_overlap}} > 0" then &
    "variable wall_key string max_wall_overlap" "variable wall_value string ${{guard_max_wall_overlap}}"
fix check_contact all check/contact every {every} step_fraction 1 action warn fast_speed ${{guard_fast_speed}} &
    walls walls ${{speed_key}} ${{speed_value}} ${{pair_key}} ${{pair_value}} ${{wall_key}} ${{wall_value}}
# the squeeze ledger of the cases: events, the energy-runaway guard, wall crossings
include ${{case_dir}}/include/squeeze_ledger.in
region bore cylinder x 0 0 {radius!r} INF INF units box
variable escaped equal count(all)-count(all,bore)
variable pp equal f_check_contact[2]
variable speed equal f_check_contact[5]
variable paddle equal f_check_contact[6]
variable barrel equal f_check_contact[7]
variable fast equal f_check_contact[8]
variable sq_wall equal f_squeeze[4]
variable sq_pair equal f_squeeze[5]
variable sq_rel equal f_squeeze[6]
thermo_style custom step atoms ke v_pp v_speed v_paddle v_barrel v_escaped v_fast &
    v_squeezes v_pressed v_crossed v_e_excess v_sq_wall v_sq_pair v_sq_rel
thermo_modify norm no lost error format float %.10g
thermo {every}
run $({every}*ceil({window!r}/dt/{every}))
print "MAP-DONE escaped ${{escaped}}"
"""


def barrel_stl() -> str:
    """Cylinder r = BARREL_RADIUS about x, 0 <= x <= SLICE_LENGTH, normals inward (towards the particles)."""
    angles = np.linspace(0, 2 * np.pi, SEGMENTS + 1)
    y, z = BARREL_RADIUS * np.cos(angles), BARREL_RADIUS * np.sin(angles)
    facets = []
    for k in range(SEGMENTS):
        a0, a1 = (0.0, y[k], z[k]), (0.0, y[k + 1], z[k + 1])
        b0, b1 = (SLICE_LENGTH, y[k], z[k]), (SLICE_LENGTH, y[k + 1], z[k + 1])
        facets += [(a0, b0, b1), (a0, b1, a1)]
    return stl("barrel", facets)


def paddle_profile(clearance: float = CLEARANCE) -> ScrewProfile:
    """The paddle's section: the paper's two-flight self-wiping (Booy) profile, its root radius scaled
    to this barrel, its tips `clearance` from the barrel."""
    return ScrewProfile(outer_radius=BARREL_RADIUS - clearance, root_radius=ROOT_RADIUS)


def paddle_outline(profile: ScrewProfile) -> np.ndarray:
    """The section's outline (y, z), counter-clockwise, tips on the z axis: at the ends of its tip,
    flank and root arcs and about every PADDLE_STEP_DEG between (none closer than half a step to an
    end). The profile's tip 0, its local +u axis, is +z."""
    kw = profile.tip_angle
    corners = np.mod([k * np.pi / 2 + sign * kw / 2 for k in range(4) for sign in (-1, 1)], 2 * np.pi)
    step = np.radians(PADDLE_STEP_DEG)
    grid = np.arange(0.0, 2 * np.pi, step)
    apart = np.abs(np.angle(np.exp(1j * (grid[:, None] - corners[None, :])))).min(axis=1) >= step / 2
    phi = np.sort(np.concatenate([grid[apart], corners]))
    r = profile.radius(phi)
    u, v = r * np.cos(phi), r * np.sin(phi)
    return np.column_stack((-v, u))   # (u, v) -> (y, z) = (-v, u): a quarter turn, orientation kept


def paddle_stl(clearance: float = CLEARANCE) -> str:
    """The paddle: the profile extruded over the slice in PADDLE_ROWS rows, open at the periodic ends
    x = 0 and SLICE_LENGTH, its faces' normals (vertex order) outward, so that a particle centre inside
    it is a wall crossing for fix squeeze/ledger."""
    outline = paddle_outline(paddle_profile(clearance))
    rows = np.linspace(0.0, SLICE_LENGTH, PADDLE_ROWS + 1)
    facets = []
    for xa, xb in zip(rows[:-1], rows[1:]):
        for (y0, z0), (y1, z1) in zip(outline, np.roll(outline, -1, axis=0)):
            a0, a1 = (xa, y0, z0), (xa, y1, z1)
            b0, b1 = (xb, y0, z0), (xb, y1, z1)
            facets += [(a0, a1, b1), (a0, b1, b0)]
    return stl("paddle", facets)


def fill_positions(d_mean: float, fill_top: float, clearance: float, seed: int = JITTER_SEED) -> np.ndarray:
    """Sites of a simple cubic lattice (spacing about 1.05 d that fits the periodic length a whole
    number of times) in the barrel (centres 0.6 d inside it), below z = fill_top x radius - 0.6 d and
    at least 0.6 d outside the paddle, in the order x, then y, then z fastest, each moved at random by
    up to JITTER x d along each axis."""
    spacing = SLICE_LENGTH / math.floor(SLICE_LENGTH / (1.05 * d_mean))
    n_x = round(SLICE_LENGTH / spacing)
    n_r = math.ceil(BARREL_RADIUS / spacing)
    x, y, z = np.meshgrid(np.arange(n_x) * spacing, np.arange(-n_r, n_r + 1) * spacing,
                          np.arange(-n_r, n_r + 1) * spacing, indexing="ij")
    x, y, z = x.ravel(), y.ravel(), z.ravel()
    keep = (np.hypot(y, z) < BARREL_RADIUS - 0.6 * d_mean) & (z < fill_top * BARREL_RADIUS - 0.6 * d_mean)
    profile = paddle_profile(clearance)
    u, v = z[keep], -y[keep]      # the profile's local frame (paddle_outline)
    outside = np.hypot(u, v) > profile.radius(np.arctan2(v, u))
    clear = profile.distance(np.column_stack((u, v))) > 0.6 * d_mean
    chosen = np.flatnonzero(keep)[outside & clear]
    sites = np.column_stack((x[chosen], y[chosen], z[chosen]))
    # each site moved by up to ±JITTER x d (seeded): the x layers of the lattice do not move in step;
    # x wrapped into the periodic box (create_atoms single drops a site outside it)
    sites += np.random.default_rng(seed).uniform(-JITTER * d_mean, JITTER * d_mean, sites.shape)
    sites[:, 0] = np.mod(sites[:, 0], SLICE_LENGTH)
    return sites


def fill_in(positions: np.ndarray) -> str:
    return "".join(f"create_atoms 1 single {x!r} {y!r} {z!r} units box\n" for x, y, z in positions.tolist())


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
    seed: int = JITTER_SEED        # of the fill's jitter
    clearance: float = math.nan    # m, paddle tip to barrel
    gap_ratio: float = math.nan    # clearance / largest particle
    squeeze: bool = False          # clearance < smallest particle: overlap and speed guards off (guards.in)
    simulated: float = math.nan    # s, steps x dt
    fast_events: int = 0           # excursions above guards.in's guard_fast_speed (counted, not stopped)
    # the squeeze ledger (ledger_of): events, open, events_per_s, peak_wall, peak_pair, max_release_speed,
    # crossings, max_energy_excess, first_crossings
    ledger: dict = field(default_factory=dict)


def ledger_of(rows: dict[str, np.ndarray], simulated: float, log: str) -> dict:
    """The squeeze ledger of a run from its thermo columns and the crossings its log names: events
    (closed), open (still pressed at the end), events_per_s ((closed + open) / simulated time: squeezes
    begun per second), peak_wall and peak_pair (δ/R, the deepest of the closed events),
    max_release_speed (m/s, of the closed events), crossings, max_energy_excess (the largest (KE - B) /
    turnover after the first step, or the runaway's), first_crossings (as the log names them)."""
    def last(key: str) -> float:
        return float(rows[key][-1]) if key in rows and rows[key].size else math.nan

    def count(key: str) -> int:
        return int(last(key)) if math.isfinite(last(key)) else 0
    events, pressed = count("squeezes"), count("pressed")
    crossings = [line.split(": ", 1)[1] for line in log.splitlines()
                 if line.startswith("WARNING") and "squeeze/ledger" in line and ": crossing " in line]
    after_start = rows["e_excess"][rows["Step"] > rows["Step"][0]] if "e_excess" in rows else np.array([])
    excess = float(np.nanmax(after_start)) if after_start.size else math.nan
    runaway = re.search(r"kinetic energy runaway: .*? by (\S+) of the energy turnover", log)
    if runaway:
        excess = float(runaway.group(1))
    return {"events": events, "open": pressed,
            "events_per_s": (events + pressed) / simulated if simulated > 0 else math.nan,
            "peak_wall": last("sq_wall"), "peak_pair": last("sq_pair"), "max_release_speed": last("sq_rel"),
            "crossings": max(count("crossed"), len(crossings)), "max_energy_excess": excess,
            "first_crossings": crossings[:3]}


def run_scene(case: str, fraction: float, window: float, workdir: Path, nprocs: int = 1, every: int = 100,
              seed: int = JITTER_SEED) -> Run:
    workdir.mkdir(parents=True, exist_ok=True)
    shape = geometry(case)
    (workdir / "barrel.stl").write_text(barrel_stl())
    (workdir / "paddle.stl").write_text(paddle_stl(shape.clearance))
    variables = {k: v for k, v in dict(DEFAULTS, **CASES[case]).items() if k not in SCENE_PARAMETERS}
    d_mean, fill_top = float(variables["d_mean"]), float(variables["fill_top"])   # type: ignore[arg-type]
    (workdir / "fill.in").write_text(fill_in(fill_positions(d_mean, fill_top, shape.clearance, seed)))
    (workdir / "in.scene").write_text(SCENE.format(
        case_dir=ROOT / "cases", length=SLICE_LENGTH, box=BARREL_RADIUS + 0.001, radius=BARREL_RADIUS,
        fraction=fraction, every=every, window=window,
        clearance=shape.clearance,
        mode="a squeeze case: overlap and speed guards off" if shape.squeeze else "a passing case: overlap and speed guards on"))
    for stale in ("log.lammps", "squeezes.txt"):
        (workdir / stale).unlink(missing_ok=True)
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
    run = Run(case=case, fraction=fraction, stable=False, reason="", seconds=seconds, clearance=shape.clearance,
              gap_ratio=shape.ratio, squeeze=shape.squeeze, seed=seed)
    estimate = re.search(r"critical step estimate (\S+) s .*?time step (\S+) s", log)
    if estimate:
        run.estimate, run.timestep = float(estimate.group(1)), float(estimate.group(2))
    thermo = parse_thermo(log)
    rows: dict[str, np.ndarray] = {}
    if thermo:
        rows = {key: np.concatenate([t[key] for t in thermo if key in t]) for key in thermo[0]}
        run.steps = int(rows["Step"][-1])
        run.particles = int(rows["Atoms"][0])
        run.max_pair_overlap = float(np.nanmax(rows["pp"]))
        run.max_speed = float(np.nanmax(rows["speed"]))
        run.max_wall_overlap = {"paddle": float(np.nanmax(rows["paddle"])), "barrel": float(np.nanmax(rows["barrel"]))}
        run.fast_events = int(rows["fast"][-1])
    errors = [line for line in (log + proc.stdout).splitlines() if line.startswith("ERROR")]
    done = re.search(r"MAP-DONE escaped (\d+)", log)
    if proc.returncode != 0 or not done:
        message = errors[0] if errors else f"exit {proc.returncode}"
        if "moves at" in message:
            run.reason = "kinetic-energy blow-up"
        elif "above max_pair_overlap" in message or "above max_wall_overlap" in message:
            run.reason = "overlap guard"
        elif "kinetic energy runaway" in message:
            run.reason = "energy runaway"
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
    run.simulated = run.steps * run.timestep
    run.ledger = ledger_of(rows, run.simulated, log) if rows else {}
    return run


def largest_stable(stable_at, fractions: list[float], bisections: int, floor: float | None = None) -> tuple[float, float]:
    """Largest stable fraction: the largest rung of the ladder below its smallest unstable rung (a
    stable rung above an unstable one does not count), refined by bisection (geometric midpoints)
    towards that unstable rung: (largest stable, smallest unstable) found; nan when none. When the
    smallest rung is unstable, halved rungs below it down to `floor` are tried first."""
    results = {f: stable_at(f) for f in sorted(fractions)}
    unstable = [f for f, ok in results.items() if not ok]
    high = min(unstable) if unstable else math.nan
    below = [f for f, ok in results.items() if ok and not f > high]
    if not unstable:
        return max(fractions), math.nan
    if below:
        low = max(below)
    else:
        low, f = math.nan, min(fractions) / 2
        while floor is not None and f >= floor * (1 - 1e-9):
            if stable_at(f):
                low = f
                break
            high, f = f, f / 2
        if not math.isfinite(low):
            return math.nan, high
    for _ in range(bisections):
        middle = math.sqrt(low * high)
        if stable_at(middle):
            low = middle
        else:
            high = middle
    return low, high


def map_case(case: str, fractions: list[float], bisections: int, window: float, out: Path, nprocs: int,
             runs: list[Run], floor: float | None = None, seed: int = JITTER_SEED) -> dict:
    def stable_at(fraction: float) -> bool:
        run = run_scene(case, fraction, window, out / case / f"f{fraction:.5g}", nprocs, seed=seed)
        runs.append(run)
        ledger = run.ledger
        print(f"  {case:14s} f = {fraction:<8.4g} {'stable' if run.stable else 'UNSTABLE: ' + run.reason:32s} "
              f"pp {run.max_pair_overlap:.3g}  pg {max(run.max_wall_overlap.values(), default=math.nan):.3g}  "
              f"squeezes {ledger.get('events', 0)} ({ledger.get('events_per_s', math.nan):.3g}/s)  "
              f"crossings {ledger.get('crossings', 0)}  ({run.seconds:.0f} s)", flush=True)
        return run.stable
    low, high = largest_stable(stable_at, fractions, bisections, floor)
    return summarise(case, low, high, [r for r in runs if r.case == case], window, seed)


def summarise(case: str, low: float, high: float, runs: list[Run], window: float, seed: int = JITTER_SEED) -> dict:
    shape = geometry(case)
    unstable = [r for r in runs if math.isclose(r.fraction, high)]
    stable = [r for r in runs if r.stable]
    return {"case": case, "clearance": shape.clearance, "gap_ratio": shape.ratio, "squeeze": shape.squeeze,
            "window_s": window, "seed": seed, "largest_stable_fraction": low, "smallest_unstable_fraction": high,
            # half the largest stable step, at most the 20 % the guards allow
            "safe_fraction": min(0.2, low / 2) if math.isfinite(low) else math.nan,
            "unstable_reason": unstable[0].reason if unstable else "",
            # wall crossings are counted, not fatal: the stable fractions at which any happened
            "stable_fractions_with_crossings": sorted(r.fraction for r in stable if r.ledger.get("crossings", 0) > 0)}


RESOLVED_DEPTH = 0.1   # deepest particle-wall δ/R within this of the finest stable run's
RESOLVED_RATE = 2.0    # and squeezes begun per second within this factor of it (or both none)


def enrich(entry: dict, runs: list[Run]) -> dict:
    """What the runs of a case say beyond its edge: `stable_above_edge`, the stable fractions above the
    smallest unstable one (stability need not be monotone in f), and `ledger_resolved_up_to`, the
    largest stable fraction up to the edge at which this and every stable run below it squeeze as the
    finest stable run does (RESOLVED_DEPTH, RESOLVED_RATE): the time step leaves the squeezes as they are."""
    mine = sorted((r for r in runs if r.case == entry["case"] and r.stable and r.ledger), key=lambda r: r.fraction)
    high, low = entry["smallest_unstable_fraction"], entry["largest_stable_fraction"]
    resolved = math.nan
    if mine and math.isfinite(low):
        finest = mine[0]

        def depth(r: Run) -> float:
            return max(r.max_wall_overlap.values(), default=math.nan)

        def agrees(r: Run) -> bool:
            rate, reference = r.ledger["events_per_s"], finest.ledger["events_per_s"]
            same_rate = rate == reference == 0 or (reference > 0 and 1 / RESOLVED_RATE <= rate / reference <= RESOLVED_RATE)
            return abs(depth(r) - depth(finest)) <= RESOLVED_DEPTH and same_rate
        for r in mine:
            if r.fraction > low * (1 + 1e-9) or not agrees(r):
                break
            resolved = r.fraction
    return dict(entry, stable_above_edge=sorted(r.fraction for r in mine if r.fraction > high),
                ledger_resolved_up_to=resolved)


def _at(runs: list[Run], case: str, fraction: float) -> Run | None:
    at = [r for r in runs if r.case == case and math.isfinite(fraction) and math.isclose(r.fraction, fraction)]
    return at[0] if at else None


def _rungs(runs: list[Run]) -> list[float]:
    """The ladder's rungs among the runs: the fractions 0.05 x 2^k (halved ones included), not the bisections'."""
    return sorted({r.fraction for r in runs if math.isclose(math.log2(r.fraction / 0.05), round(math.log2(r.fraction / 0.05)),
                                                           abs_tol=1e-9)})


SHORT_REASONS = {"energy runaway": "runaway", "kinetic-energy blow-up": "speed", "overlap guard": "overlap",
                 "lost atoms": "lost", "NaN": "NaN"}


def table(summary: list[dict], runs: list[Run], reference: float) -> str:
    lines = ["| case | gap (mm) | gap / d_max | squeeze | largest stable f | smallest unstable f | why | "
             "stable above it | safe f | ledger as at the finest f up to | estimate (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for s in summary:
        r = _at(runs, s["case"], reference)
        above = ", ".join(f"{f:.3g}" for f in s.get("stable_above_edge", [])) or "–"
        lines.append(f"| {s['case']} | {1e3 * s.get('clearance', math.nan):.3g} | {s.get('gap_ratio', math.nan):.3g} | "
                     f"{'yes' if s.get('squeeze') else 'no'} | {s['largest_stable_fraction']:.3g} | "
                     f"{s['smallest_unstable_fraction']:.3g} | {s.get('unstable_reason', '') or '–'} | {above} | "
                     f"{s['safe_fraction']:.3g} | {s.get('ledger_resolved_up_to', math.nan):.3g} | "
                     f"{r.estimate if r else math.nan:.3g} |")
    lines += ["", f"Squeeze ledger and overlaps at f = {reference:g} and at the largest stable f:", "",
              "| case | f | pp δ/R | pg δ/R (paddle, barrel) | events (open) | begun per s | peak wall, pair δ/R (events) | "
              "max release (m/s) | fast | crossings | max energy excess |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    for s in summary:
        for fraction in dict.fromkeys([reference, s["largest_stable_fraction"]]):
            r = _at(runs, s["case"], fraction)
            if r is None:
                continue
            g = r.ledger
            ledger = (f"{g['events']} ({g['open']}) | {g['events_per_s']:.3g} | {g['peak_wall']:.3g}, {g['peak_pair']:.3g} | "
                      f"{g['max_release_speed']:.3g} | {r.fast_events} | {g['crossings']} | {g['max_energy_excess']:.3g}"
                      if g else "– | – | – | – | – | – | –")
            lines.append(f"| {s['case']} | {r.fraction:.3g} | {r.max_pair_overlap:.3g} | "
                         f"{r.max_wall_overlap.get('paddle', math.nan):.3g}, {r.max_wall_overlap.get('barrel', math.nan):.3g} | "
                         f"{ledger} |")
    rungs = _rungs(runs)
    lines += ["", "Along the ladder: squeezes begun per second and the deepest particle-wall δ/R (check/contact) of "
              "each run; an unstable run: why it stopped:", "",
              "| case | " + " | ".join(f"f = {f:g}" for f in rungs) + " |", "|---|" + "---|" * len(rungs)]
    for s in summary:
        cells = []
        for f in rungs:
            r = _at(runs, s["case"], f)
            if r is None:
                cells.append("")
            elif not r.stable:
                cells.append(SHORT_REASONS.get(r.reason, r.reason))
            else:
                cells.append(f"{r.ledger.get('events_per_s', math.nan):.3g}/s, "
                             f"{max(r.max_wall_overlap.values(), default=math.nan):.2g}")
        lines.append(f"| {s['case']} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def figure(summary: list[dict], runs: list[Run], reference: float, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = [s["case"] for s in summary]
    labels = [f"{s['case']} ({s.get('gap_ratio', math.nan):.2g})" for s in summary]
    x = np.arange(len(names))
    fig, ((top, overlaps), (events, depth)) = plt.subplots(2, 2, figsize=(14, 9))
    top.bar(x, [s["largest_stable_fraction"] for s in summary], color="tab:green", label="largest stable")
    top.scatter(x, [s["smallest_unstable_fraction"] for s in summary], color="tab:red", marker="v",
                label="smallest unstable", zorder=3)
    for k, s in enumerate(summary):
        above = s.get("stable_above_edge", [])
        top.scatter([x[k]] * len(above), above, color="tab:green", marker="o", facecolors="none",
                    label="stable above it" if above and "stable above it" not in top.get_legend_handles_labels()[1] else None)
    top.axhline(0.2, color="k", lw=0.8, ls="--", label="guard: 0.2")
    top.axhline(0.1, color="k", lw=0.8, ls=":", label="the cases: 0.1")
    top.set_yscale("log")
    top.set_ylabel("dt / check/contact estimate")
    top.set_xticks(x, labels, rotation=45, ha="right", fontsize=8)
    top.legend(fontsize=7)
    at = [_at(runs, name, reference) for name in names]
    overlaps.bar(x - 0.25, [r.max_pair_overlap if r else math.nan for r in at], 0.25, label="particle-particle")
    overlaps.bar(x, [r.max_wall_overlap.get("paddle", math.nan) if r else math.nan for r in at], 0.25, label="paddle")
    overlaps.bar(x + 0.25, [r.max_wall_overlap.get("barrel", math.nan) if r else math.nan for r in at], 0.25, label="barrel")
    overlaps.axhline(0.5, color="k", lw=0.8, ls="--", label="passing cases' overlap guard: 0.5")
    overlaps.set_ylabel(f"largest δ/R at f = {reference:g}")
    overlaps.set_xticks(x, labels, rotation=45, ha="right", fontsize=8)
    overlaps.legend(fontsize=7)
    for k, name in enumerate(names):
        mine = sorted((r for r in runs if r.case == name and r.stable and r.ledger), key=lambda r: r.fraction)
        if not any(r.ledger.get("events_per_s", 0) > 0 for r in mine):
            continue
        style = dict(marker="o", ms=3, lw=1, color=plt.get_cmap("tab20")(k % 20), label=name)
        events.plot([r.fraction for r in mine], [r.ledger["events_per_s"] for r in mine], **style)
        depth.plot([r.fraction for r in mine], [max(r.max_wall_overlap.values(), default=math.nan) for r in mine], **style)
    for axis, label in ((events, "squeezes begun per simulated second"), (depth, "deepest particle-wall δ/R")):
        axis.set_xscale("log")
        axis.set_xlabel("dt / check/contact estimate (stable runs)")
        axis.set_ylabel(label)
        axis.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def write(out: Path, header: dict, summary: list[dict], runs: list[Run], reference: float) -> str:
    out.mkdir(parents=True, exist_ok=True)
    summary = [enrich(entry, runs) for entry in summary]
    (out / "stability_map.json").write_text(json.dumps(
        dict(header, summary=summary, runs=[asdict(r) for r in runs]), indent=1))
    text = table(summary, runs, reference)
    (out / "stability_map.md").write_text(text)
    figure(summary, runs, reference, out / "stability_map.png")
    return text


def merge(paths: list[Path], out: Path) -> int:
    summary: dict[str, dict] = {}
    runs: dict[str, list[Run]] = {}
    fractions: set[float] = set()
    for path in paths:
        data = json.loads(path.read_text())
        for entry in data["summary"]:
            summary[entry["case"]] = entry
            runs[entry["case"]] = [Run(**r) for r in data["runs"] if r["case"] == entry["case"]]
    ordered = [summary[c] for c in CASES if c in summary]
    all_runs = [r for c in CASES if c in runs for r in runs[c]]
    fractions = {r.fraction for r in all_runs}
    reference = 0.1 if 0.1 in fractions else min(fractions)
    print(write(out, {"merged_from": [str(p) for p in paths]}, ordered, all_runs, reference))
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated, from: " + ", ".join(CASES))
    parser.add_argument("--fractions", default="0.05,0.1,0.2,0.4,0.8,1.6,3.2")
    parser.add_argument("--bisections", type=int, default=3)
    parser.add_argument("--floor", type=float, default=0.0125,
                        help="when the smallest fraction is unstable, halve it down to this one")
    parser.add_argument("--seed", type=int, default=JITTER_SEED, help="of the fill's jitter (the same for every run)")
    parser.add_argument("--window", type=float, default=0.02, help="simulated time per run, s")
    parser.add_argument("--np", type=int, default=1)
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--merge", type=Path, nargs="+", default=None, metavar="JSON",
                        help="no runs: merge earlier results (a case in a later file replaces it in an earlier "
                             "one) into --out's JSON, tables and figure")
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
    header = {"window_s": args.window, "fractions": fractions, "bisections": args.bisections, "floor": args.floor,
              "seed": args.seed}
    runs: list[Run] = []
    summary = []
    for case in cases:
        try:
            summary.append(map_case(case, fractions, args.bisections, args.window, out, args.np, runs, args.floor,
                                    args.seed))
        except RuntimeError as failure:   # not instability: report it and go on with the other cases
            print(f"  {case}: {failure}", flush=True)
            summary.append(dict(summarise(case, math.nan, math.nan, [], args.window, args.seed), error=str(failure)))
        (out / "stability_map.json").write_text(json.dumps(
            dict(header, summary=summary, runs=[asdict(r) for r in runs]), indent=1))
    print(write(out, header, summary, runs, reference))
    print(f"written: {out}/stability_map.json, stability_map.md, stability_map.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
