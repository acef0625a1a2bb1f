"""Prepare and run one granulator case, then print its summary table.

    tsg-run-case periodic --scale demo --out runs/periodic-demo [--np 2] [-v name value ...] [--debug]

Preparation: builds the meshes the scale needs (meshes/, gmsh) and, for the periodic case, places
the hold-up mass in the free space (cases/free_space.py). Then runs `lmp -in cases/in.tsg_<case>`
(under mpirun with --np > 1) with the scale's variables plus yours (-v overrides any of them), and
prints mass flow at both sensors, mean residence time per element type and the time-averaged solid
fraction per element. Exit status 1 when lmp fails (the error is printed) or when particles escaped;
2 for a bad option or variable (one line naming it, its value and what is allowed), checked before
any preparation. The run directory gets params.json: every parameter of the run (docs/cases.md),
and lmp.vars: the variables given to lmp, one "NAME VALUE" per line. --prepare-only stops there, for
a job script that runs lmp itself (cases/slurm/segment.sh, TSG_PREPARE).
"""
from __future__ import annotations

import argparse
import json
import math
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from tsg_analysis.liggghts_log import parse_thermo
from tsg_analysis.run import Run
from tsg_analysis.run_files import mesh_zones
from tsg_analysis.summary import summary_table
from tsg_cases import prepared, states
from tsg_cases.case_parameters import ParameterError, case_input, check_names, check_values, defined_variables
from tsg_cases.command_line import run_reporting
from tsg_cases.launcher import ROOT, LauncherError, first_error, lmp_command, lmp_environment
from tsg_cases.progress import Heartbeat, follow
from tsg_cases.psd import size_classes
from tsg_meshes.build import exclusive_build, mesh_dir_name
from tsg_meshes.machine import MACHINE_FILE, machine_file_complete
from tsg_meshes.profile import profile_for_clearance

CONFIGS = {"periodic": "consigma1-periodic", "nonperiodic": "consigma1-nonperiodic", "full": "consigma1-full"}
# Scales. demo: coarse particles so that the periodic case gives per-element results in minutes on
# 2 cores (docs/cases.md explains the choices); paper: the seed paper's 400 um particles. Both with
# the mesh tolerance at 1 % of the smallest radius (demo 0.42 mm -> 4 um, paper 0.1 mm -> 1 um).
SCALES: dict[str, dict[str, Any]] = {
    # demo: a clearance-scaled machine (docs/geometry.md). The paper's gaps (0.44 mm tip to
    # barrel; 0.35 mm screw to screw in a section, 0.17 mm in 3D between conveying flights) are far
    # smaller than the demo's 1 mm particles (largest 1.16 mm), so a prescribed screw pinches them
    # whatever the contact law; and where two staggered discs meet, screw 1's disc and screw 2's
    # next disc slide past each other in one plane (a scissor, any clearance). Same barrel and centre
    # distance, smaller screws: tip to barrel 1.4 mm, screw to screw 2.8 mm in a section = 1.44 mm
    # in 3D between conveying flights, and a 1.4 mm spacer between staggered discs: every gap
    # >= 1.2 x the largest particle; the paper's friction and guards apply. The machine follows the
    # particles (machine_clearances): -v d_mean 0.0015 gets 2.1 / 4.2 / 2.1 mm.
    "demo": {"tolerance": 4e-6, "gap_factor": 1.2, "holdup_g": prepared.DEMO_HOLDUP_G,
             # skin 0.2 d: no squeezes on this machine, few list builds (the 0.4 d of the case files, for
             # the paper's squeezing machine, is no faster here: docs/performance.md)
             "vars": {"d_mean": 0.001, "dt_fraction": 0.2, "thermo_every": 2000, "stats_every": 2000,
                      "skin_fraction": 0.2},
             "times": {"periodic": {"t_startup": 0.1, "t_sample": 0.2}, "nonperiodic": {"t_run": 0.5},
                       "full": {"t_sample": 0.5, "t_max_startup": 10.0}}},
    "paper": {"tolerance": 1e-6, "gap_factor": None, "holdup_g": prepared.PAPER_HOLDUP_G,
              "vars": {"d_mean": 0.0004, "dt_fraction": 0.1, "thermo_every": 10000, "stats_every": 10000},
              "times": {"periodic": {"t_startup": 0.5, "t_sample": 1.0}, "nonperiodic": {"t_run": 5.0},
                        "full": {"t_sample": 1.0, "t_max_startup": 10.0}}},
}
PSD_CLASSES = 7   # classes of the fill's PSD (free_space.fill)
DEFAULT_FILL_SEED = 12345
MAX_FEED_SEED = 2_000_000   # 10000 + 1000 x seed stays below 2^31


class UserError(Exception):
    """A mistake in the options: one line for the user, no traceback (unless --debug)."""


def machine_clearances(gap_factor: float | None, d_mean: float, psd_sigma: float) -> tuple[float | None, float | None, float]:
    """(flight tip to barrel, screw to screw in a section, spacer between staggered discs) in m:
    the paper's machine for gap_factor None, else gap = gap_factor x the largest particle of the
    PSD, rounded up to 0.1 mm, for the tip and the spacer, and 2 x gap in the section between the
    screws (the 3D gap between conveying flights is 0.51-0.52 x the section gap, measured:
    docs/geometry.md). --clearances replaces all three."""
    if gap_factor is None:
        return None, None, 0.0
    largest = d_mean * float(size_classes(psd_sigma, PSD_CLASSES)[0].max())
    gap = round(math.ceil(round(gap_factor * largest / 1e-4, 6)) * 1e-4, 10)
    return gap, 2 * gap, gap


def build_meshes(config: str, tolerance: float, clearance: tuple[float | None, float | None, float]) -> Path:
    """The scale's mesh directory under build/meshes, built if missing or incomplete; `clearance` is
    (flight tip to barrel, screw to screw, spacer between staggered discs) in m, None (0 for the
    spacer) for the paper's."""
    out = ROOT / "build" / "meshes" / mesh_dir_name(config, tolerance, *clearance)
    with exclusive_build(out):      # runs started together build it once
        if not (out / "zones.txt").is_file() or not machine_file_complete(out):
            options = ["--tolerance", str(tolerance)]
            for option, value in zip(("--clearance", "--screw-clearance", "--disc-gap"), clearance):
                options += [option, str(value)] if value else []
            proc = subprocess.run([sys.executable, "-m", "tsg_meshes", "build", config, str(out), *options],
                                  capture_output=True, text=True)
            if proc.returncode != 0:
                last = proc.stderr.strip().splitlines()[-1:] or ["no message"]
                raise UserError(f"building the meshes {out} failed: {last[0]}")
    return out


def read_lmp_vars(run_dir: Path) -> dict[str, str]:
    """The variables a prepared run passes to lmp: its lmp.vars (written by `run`), NAME -> VALUE."""
    path = run_dir / "lmp.vars"
    if not path.is_file():
        raise UserError(f"{path}: no such file (a run directory prepared by tsg-run-case has one)")
    variables = {}
    for number, line in enumerate(path.read_text().splitlines(), 1):
        name, _, value = line.partition(" ")
        if not name or not value:
            raise UserError(f"{path}:{number}: {line!r} is not allowed: one 'NAME VALUE' per line")
        variables[name] = value
    return variables


def git_commit() -> str | None:
    try:
        proc = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True)
    except FileNotFoundError:   # no git installed (the container image has none): the commit is unknown
        return None
    return proc.stdout.strip() if proc.returncode == 0 else None


def parse(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="tsg-run-case", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("case", choices=sorted(CONFIGS))
    parser.add_argument("--scale", choices=sorted(SCALES), default="demo")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--np", type=int, default=1, help="MPI ranks")
    parser.add_argument("--holdup-g", type=float, help="hold-up mass of the periodic domain, g")
    parser.add_argument("--seed", type=int, default=None,
                        help="seed of the run's randomness: the static fill (periodic; default 12345), or the "
                             "particle generation (nonperiodic, full: seed_psd and seed_insert become the two "
                             "primes after 10000 + 1000 x seed; default: the inputs' 10007 and 10009)")
    parser.add_argument("--feed-at", default="inlet",
                        help="where particles are generated (full case): 'inlet' or 'element:N' (zone N, e.g. element:7 as the paper)")
    parser.add_argument("--clearances", type=float, nargs=3, metavar=("TIP", "SCREW", "SPACER"),
                        help="the machine's gaps in m instead of the scale's: flight tip to barrel, screw to screw "
                             "in an axial section, spacer between staggered discs (0: none). Same barrel and centre "
                             "distance: the screws' outer radius is the bore radius - TIP, their root radius the "
                             "centre distance - outer radius - SCREW")
    parser.add_argument("--mesh-tolerance", type=float,
                        help="mesh tolerance in m instead of the scale's (1 %% of the smallest radius)")
    parser.add_argument("-v", "--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"))
    parser.add_argument("--from-state", type=Path, metavar="STATE_DIR",
                        help="start from a kept state (cases/states.py): its fill and seed, continued from the end "
                             "of its start-up; the measurements run t_sample from there")
    parser.add_argument("--prepare-only", action="store_true",
                        help="prepare the run directory (meshes, fill or feed regions, params.json, lmp.vars) and "
                             "stop before lmp: for job scripts that run lmp themselves (cases/slurm/segment.sh, TSG_PREPARE)")
    parser.add_argument("--debug", action="store_true", help="show the Python traceback of an error")
    return parser.parse_args(argv)


def check_options(args: argparse.Namespace) -> None:
    """Every option checked before any expensive preparation (meshes, fill)."""
    if args.mesh_tolerance is not None and not 0.0 < args.mesh_tolerance < 1e-3:
        raise UserError(f"--mesh-tolerance {args.mesh_tolerance} is not allowed: a length in m, 0 < tolerance < 1e-3")
    if args.clearances is not None:
        tip, screw, spacer = args.clearances
        for name, value, low in (("TIP", tip, "0 <"), ("SCREW", screw, "0 <"), ("SPACER", spacer, "0 <=")):
            if not (0.0 <= value if name == "SPACER" else 0.0 < value) or not value <= 5e-3:
                raise UserError(f"--clearances {' '.join(map(str, args.clearances))}: {name} = {value} is not allowed: "
                                f"a gap in m, {low} gap <= 0.005")
        try:
            profile_for_clearance(tip, screw)
        except ValueError as problem:
            raise UserError(f"--clearances {' '.join(map(str, args.clearances))} is not allowed: {problem}") from None
    if args.holdup_g is not None and not 0.0 < args.holdup_g < 100.0:
        raise UserError(f"--holdup-g {args.holdup_g} is not allowed: hold-up mass in g, 0 < mass < 100")
    if args.np < 1:
        raise UserError(f"--np {args.np} is not allowed: number of MPI ranks, >= 1")
    if args.seed is not None and args.case == "periodic" and not 0 <= args.seed < 2**32:
        raise UserError(f"--seed {args.seed} is not allowed: 0 <= seed < 2^32")
    if args.seed is not None and args.case != "periodic":
        if not 0 <= args.seed <= MAX_FEED_SEED:
            raise UserError(f"--seed {args.seed} is not allowed for the {args.case} case: 0 <= seed <= {MAX_FEED_SEED} "
                            "(LIGGGHTS' generation seeds are 32-bit primes)")
        twice = [name for name, _ in args.var if name in ("seed_psd", "seed_insert")]
        if twice:
            raise UserError(f"--seed {args.seed} and -v {twice[0]} both set the generation seeds: give one of them")
    if args.out.exists() and not args.out.is_dir():
        raise UserError(f"--out {args.out}: is a file, not a directory")
    if args.from_state is not None:
        check_state(args)


# variables a run from a kept state takes from the state (its start-up, its fill and so its machine):
# given as well, one of them would not apply
STATE_VARIABLES = ("start", "restart_file", "t_startup", "write_state", "d_mean", "psd_sigma")


def check_state(args: argparse.Namespace) -> None:
    """--from-state: a state of this case and scale; the fill seed is the state's."""
    try:
        state = states.read(args.from_state)
    except states.StateError as problem:
        raise UserError(str(problem)) from None
    if (state.case, state.scale) != (args.case, args.scale):
        raise UserError(f"--from-state {args.from_state}: a state of the {state.case} case at {state.scale} scale, "
                        f"not allowed for the {args.case} case at {args.scale} scale")
    if args.seed is not None and args.seed != state.seed:
        raise UserError(f"--seed {args.seed} is not allowed with --from-state {args.from_state}: its fill has seed "
                        f"{state.seed} (leave --seed out)")
    options = [option for option, value in (("--holdup-g", args.holdup_g), ("--clearances", args.clearances),
                                            ("--mesh-tolerance", args.mesh_tolerance)) if value is not None]
    if options:
        raise UserError(f"{options[0]} is not allowed with --from-state {args.from_state}: the state's fill and machine apply")
    given = [name for name, _ in args.var if name in STATE_VARIABLES]
    if given:
        raise UserError(f"-v {given[0]} is not allowed with --from-state: the state sets {', '.join(STATE_VARIABLES)}")
    for name, value in args.var:
        if name in state.model and value != state.model[name]:
            raise UserError(f"-v {name} {value} is not allowed with --from-state {args.from_state}: the state was made with "
                            f"{name} {state.model[name]}, and its restart file keeps that model's contact history (run "
                            f"{name} {value} from its fill, or from a state made with it)")
    args.seed = state.seed
    args.state = state


def generation_seeds(seed: int) -> tuple[int, int]:
    """(seed_psd, seed_insert) of a feed case for --seed: the two smallest primes above
    10000 + 1000 x seed (LIGGGHTS takes primes > 10000; seed 0 gives the inputs' defaults 10007, 10009)."""
    def is_prime(n: int) -> bool:
        return n > 1 and all(n % k for k in range(2, math.isqrt(n) + 1))
    primes: list[int] = []
    candidate = 10000 + 1000 * seed
    while len(primes) < 2:
        candidate += 1
        if is_prime(candidate):
            primes.append(candidate)
    return primes[0], primes[1]


def planned_time(case: str, values: dict[str, str]) -> float | None:
    """Simulated time the run is planned for (the progress lines' 100 %): the full case's start-up
    ends at the steady state, so its plan is the upper bound t_max_startup + t_sample."""
    names = {"periodic": ("t_startup", "t_sample"), "nonperiodic": ("t_run",), "full": ("t_max_startup", "t_sample")}[case]
    try:
        return sum(float(values[name]) for name in names)
    except (KeyError, ValueError):
        return None


def run(args: argparse.Namespace) -> int:
    check_options(args)
    given = dict(args.var)
    check_names(given, args.case)
    scale = SCALES[args.scale]
    variables: dict[str, object] = {**scale["vars"], **scale["times"][args.case], **given}
    state: states.KeptState | None = getattr(args, "state", None)
    if state is not None:   # the start-up is the state's; restart_file is set once it is unpacked
        variables.update({"start": "restart", "t_startup": repr(state.t_startup)})
    if args.case != "periodic" and args.seed is not None:
        variables["seed_psd"], variables["seed_insert"] = generation_seeds(args.seed)
    # the values the run will use: the case's defaults under the scale's and the user's
    effective = {**defined_variables(args.case), **{k: str(v) for k, v in variables.items()}}
    check_values(effective, args.case, given)
    input_file = case_input(args.case)
    command_prefix = lmp_command(input_file, nprocs=args.np)   # checks lmp (and mpirun) before the fill
    out = args.out.resolve()
    try:
        out.mkdir(parents=True, exist_ok=True)
        (out / ".tsg-write-test").touch()
        (out / ".tsg-write-test").unlink()
    except OSError as problem:
        raise UserError(f"--out {args.out}: cannot write there ({problem.strerror})") from None
    if state is not None:
        variables["restart_file"] = states.unpack(state, out)
    preparing = Heartbeat(f"{args.case} case: meshes and "
                          f"{'the kept state' if state else 'fill' if args.case == 'periodic' else 'feed regions'}").start()

    clearances = tuple(args.clearances) if args.clearances else \
        machine_clearances(scale["gap_factor"], float(effective["d_mean"]), float(effective.get("psd_sigma", 0.05)))
    mesh_tolerance = args.mesh_tolerance or scale["tolerance"]
    mesh_dir = build_meshes(CONFIGS[args.case], mesh_tolerance, clearances)
    zones = mesh_zones(mesh_dir)
    length = float(zones.x_end[-1])
    d_mean = float(effective["d_mean"])
    rho_p = float(effective["rho_p"])        # one source: materials.in's default or -v rho_p
    if state is not None:   # the particles are the state's: no fill to place
        what = f"the kept state {state.path} (fill seed {state.seed}, t = {state.t_startup:g} s, step {state.step})"
    elif args.case == "periodic":
        holdup = (args.holdup_g or scale["holdup_g"]) * 1e-3
        include, data = prepared.fill_files(mesh_dir, d_mean, float(effective.get("psd_sigma", 0.05)), rho_p,
                                            holdup * 1e3, DEFAULT_FILL_SEED if args.seed is None else args.seed)
        prepared.write(out / "fill.in", include, "tsg-run-case", data)
        variables["fill_file"] = out / "fill.in"
        what = f"{prepared.fill_count(include)} particles ({holdup * 1e3:.3g} g)"
    else:
        try:
            x0, x1 = prepared.feed_range(args.feed_at, mesh_dir)
            prepared.write(out / "feed.in", prepared.feed_text(mesh_dir, d_mean, args.feed_at), "tsg-run-case")
        except prepared.PrepareError as problem:
            raise UserError(str(problem)) from None
        variables["feed_file"] = out / "feed.in"
        what = f"feed regions at x = {x0 * 1e3:.1f}-{x1 * 1e3:.1f} mm"
    preparing.stop()
    # the run directory is self-describing for tsg_analysis: zones, machine geometry, screw surfaces
    for name in ("zones.txt", MACHINE_FILE):
        shutil.copyfile(mesh_dir / name, out / name)
    (out / "meshes").mkdir(exist_ok=True)
    for name in ("screw1.stl", "screw2.stl"):
        link = out / "meshes" / name
        link.unlink(missing_ok=True)
        link.symlink_to(mesh_dir / name)
    variables.update({"case_dir": ROOT / "cases", "out_dir": out, "mesh_dir": mesh_dir,
                      "domain_length": repr(length)})
    if args.np > 1:
        variables.setdefault("procs_x", args.np)
    effective.update({k: str(v) for k, v in variables.items()})
    (out / "params.json").write_text(json.dumps({
        "case": args.case, "scale": args.scale,
        "seed": DEFAULT_FILL_SEED if args.seed is None and args.case == "periodic" else args.seed, "np": args.np,
        "from_state": None if state is None else {"path": str(state.path), "t_startup": state.t_startup,
                                                  "step": state.step, "command": state.command, "commit": state.commit},
        "variables": {k: str(v) for k, v in variables.items()},
        "rpm": float(effective["rpm"]), "screw_direction": int(float(effective["screw_direction"])),
        "rho_p": rho_p, "d_mean": d_mean, "mesh_dir": str(mesh_dir), "mesh_tolerance_m": mesh_tolerance,
        "zones_file": str(out / "zones.txt"),
        "machine_file": str(out / MACHINE_FILE),
        "clearances_m": {"tip_to_barrel": clearances[0], "screw_to_screw": clearances[1], "disc_spacer": clearances[2]},
        "git_commit": git_commit()}, indent=1) + "\n")
    # the same variables as lines "NAME VALUE", for a job script that runs lmp itself (segment.sh)
    (out / "lmp.vars").write_text("".join(f"{name} {value}\n" for name, value in variables.items()))
    command = command_prefix
    for name, value in variables.items():
        command += ["-var", name, str(value)]
    if args.prepare_only:
        print(f"[run] {args.case} case, {args.scale} scale, prepared: {what}, meshes {mesh_dir.name}, "
              f"variables in {out / 'lmp.vars'}", flush=True)
        return 0
    print(f"[run] {args.case} case, {args.scale} scale: {what}, meshes {mesh_dir.name}, output {out}", flush=True)
    start = time.perf_counter()
    # lmp's screen output goes to screen.txt, its log to log.lammps; a progress line every ~10 s
    # (TSG_PROGRESS_EVERY) comes from the log as it grows (cases/progress.py)
    (out / "log.lammps").unlink(missing_ok=True)     # the follower must not read a previous run's log
    with open(out / "screen.txt", "w") as screen, \
            subprocess.Popen(command, cwd=out, stdout=screen, stderr=subprocess.STDOUT, env=lmp_environment()) as proc:
        returncode = follow(proc, out / "log.lammps", planned_time(args.case, effective))
    wall = time.perf_counter() - start
    if returncode != 0:
        error = first_error(out)
        print(f"[run] lmp failed (exit {returncode}): {error or 'see ' + str(out / 'screen.txt')}", file=sys.stderr)
        return 1
    run = Run(out)
    thermo = parse_thermo(run.log)
    steps = int(sum(block["Step"][-1] - block["Step"][0] for block in thermo))
    print(f"[run] done in {wall:.0f} s ({steps} steps, {wall / max(steps, 1) * 1e3:.2f} ms/step)")
    print(summary_table(run))
    return 0


def main(argv: list[str] | None = None) -> int:
    args = parse(argv)
    return run_reporting("tsg-run-case", lambda: run(args), (UserError, ParameterError, LauncherError, OSError), args.debug)


if __name__ == "__main__":
    sys.exit(main())
