"""The case runner's and the case inputs' rows of the bad-input campaign (tests/errors/README.md).

Runner rows stop before any preparation (meshes, fill) and take about a second; `lmp -var` rows run
the case input itself and stop in validate.in, before the meshes are read."""
from __future__ import annotations

import os
from pathlib import Path

from badinput import ROOT, BadInput

BUILD = Path(os.environ.get("TSG_BUILD_DIR", ROOT / "build"))
MESHES = {case: BUILD / "meshes" / f"consigma1-{case}-5um" for case in ("periodic", "nonperiodic", "full")}
RUNNER = ["{python}", "-m", "tsg_cases.run_case"]


def runner(case: str, *options: str) -> list[str]:
    return [*RUNNER, case, "--out", "{tmp}/run", *options]


def lmp(case: str, **variables: object) -> list[str]:
    command = ["{lmp}", "-in", f"{{root}}/cases/in.tsg_{case}", "-echo", "none",
               "-var", "case_dir", "{root}/cases", "-var", "mesh_dir", str(MESHES[case]), "-var", "out_dir", "{tmp}"]
    for name, value in variables.items():
        command += ["-var", name, str(value)]
    return command


def refused(case: str, name: str, value: object, words: tuple[str, ...], why: str) -> list[BadInput]:
    """The same value refused by the runner (before the fill) and by LIGGGHTS (lmp -var)."""
    message = (f"{name} = {value} is not allowed", *words)
    return [BadInput(f"cases.run.{case}.{name}={value}", message, why=why, command=runner(case, "-v", name, str(value))),
            BadInput(f"cases.lmp.{case}.{name}={value}", ("ERROR:", *message), why=why, command=lmp(case, **{name: value}))]


CASES: list[BadInput] = [
    # misspelt or foreign names: the case's `variable ... index` lines are the list
    BadInput("cases.run.misspelt-rpm", ("-v rmp", "no variable 'rmp'", "did you mean rpm"),
             why="a misspelt variable would run with the default (rmp 300 ran at 600 rpm)",
             command=runner("periodic", "-v", "rmp", "300")),
    BadInput("cases.run.misspelt-rho", ("-v rho", "did you mean rho_p"),
             why="a misspelt material name would run with the default",
             command=runner("periodic", "-v", "rho", "1500")),
    BadInput("cases.run.unknown-name", ("-v colour", "periodic case has no variable 'colour'"),
             why="a name no case knows", command=runner("periodic", "-v", "colour", "1")),
    BadInput("cases.run.foreign-name", ("-v t_startup", "nonperiodic case has no variable 't_startup'"),
             why="a variable of another case (the non-periodic case has no start-up phase)",
             command=runner("nonperiodic", "-v", "t_startup", "0.1")),
    BadInput("cases.run.runner-set-mesh_dir", ("-v mesh_dir", "set by the runner"),
             why="the runner chooses the meshes (--scale, --mesh-tolerance); a -v would be overridden silently",
             command=runner("periodic", "-v", "mesh_dir", "/tmp")),
    BadInput("cases.run.runner-set-out_dir", ("-v out_dir", "set by the runner", "--out"),
             why="outputs go to --out", command=runner("periodic", "-v", "out_dir", "/tmp")),
    BadInput("cases.run.runner-set-domain_length", ("-v domain_length", "set by the runner"),
             why="the domain length comes from the meshes' zones.txt",
             command=runner("periodic", "-v", "domain_length", "0.2")),
    BadInput("cases.run.not-a-number", ("-v rpm abc", "not a number"),
             why="a value that is not a number", command=runner("periodic", "-v", "rpm", "abc")),
    BadInput("cases.run.nan", ("-v rho_p nan", "not a number"),
             why="NaN passes every comparison unnoticed", command=runner("periodic", "-v", "rho_p", "nan")),
    BadInput("cases.lmp.periodic.guard_fast_speed-above-guard_max_speed",
             ("ERROR:", "guard_fast_speed = 10 m/s is not allowed with guard_max_speed = 5 m/s", "lower guard_fast_speed too"),
             why="a stricter speed guard alone would leave no speeds to count events in (guards.in; after the meshes "
                 "and the fill are read)",
             command=lmp("periodic", guard_max_speed=5, guard_fast_speed=10)),
    BadInput("cases.lmp.periodic.guard_max_wall_overlap=-1", ("ERROR:", "guard_max_wall_overlap = -1 is not allowed",
                                                                 "overlap / radius, > 0", "or 0 (off)"),
             why="a negative wall-overlap bound (0 is off: the paper machine's squeezes are counted by the ledger)",
             command=lmp("periodic", guard_max_wall_overlap=-1)),
    BadInput("cases.lmp.periodic.guard_max_energy_excess=-1",
             ("ERROR:", "guard_max_energy_excess = -1 is not allowed", "fraction of the energy turnover"),
             why="a negative bound on the energy the integration may create", command=lmp("periodic", guard_max_energy_excess=-1)),
    BadInput("cases.lmp.periodic.squeeze_ledger=2", ("ERROR:", "squeeze_ledger = 2 is not allowed", "1 (the ledger) or 0"),
             why="the ledger is on or off", command=lmp("periodic", squeeze_ledger=2)),
    *refused("periodic", "neighbour_trigger", 2, ("1 (rebuild when a pair may have been missed) or 0",),
             why="the pairwise neighbour rule is on or off"),
    BadInput("cases.lmp.periodic.neighbour_trigger-stock", ("ERROR:", "neigh_modify trigger pairwise is not allowed "
                                                            "with fix wall_neighlist_screw1", "valid for half a skin only"),
             why="the stock mesh walls' lists hold for half a skin only",
             command=lmp("periodic", screw_drive="stock", neighbour_trigger=1)),
    # runner options, checked before the meshes and the fill
    BadInput("cases.run.holdup-negative", ("--holdup-g -1", "0 < mass < 100"),
             why="a negative hold-up mass (numpy ValueError before)", command=runner("periodic", "--holdup-g", "-1")),
    BadInput("cases.run.holdup-zero", ("--holdup-g 0", "0 < mass"),
             why="an empty domain measures nothing", command=runner("periodic", "--holdup-g", "0")),
    BadInput("cases.run.np-zero", ("--np 0", ">= 1"), why="no MPI ranks", command=runner("periodic", "--np", "0")),
    BadInput("cases.run.seed-negative", ("--seed -1", "0 <= seed"),
             why="numpy seeds are unsigned", command=runner("periodic", "--seed", "-1")),
    BadInput("cases.run.feed-seed-too-large", ("--seed 2000001", "for the nonperiodic case", "0 <= seed <= 2000000"),
             why="the generation seeds (primes after 10000 + 1000 x seed) must stay 32-bit for LIGGGHTS",
             command=runner("nonperiodic", "--seed", "2000001")),
    BadInput("cases.run.feed-seed-twice", ("--seed 3 and -v seed_insert", "give one of them"),
             why="two sources for one generation seed: one would be silently ignored",
             command=runner("full", "--seed", "3", "-v", "seed_insert", "10007")),
    BadInput("cases.run.clearances-zero", ("--clearances 0.0 0.0028 0.0014", "TIP = 0.0", "0 < gap <= 0.005"),
             why="screws that touch the barrel", command=runner("periodic", "--clearances", "0", "2.8e-3", "1.4e-3")),
    BadInput("cases.run.clearances-spacer", ("SPACER = 0.006", "0 <= gap <= 0.005"),
             why="a spacer wider than a disc", command=runner("periodic", "--clearances", "1.4e-3", "2.8e-3", "6e-3")),
    BadInput("cases.run.clearances-no-land", ("--clearances 0.0017 0.0042 0.0021 is not allowed", "no tip land"),
             why="screws whose profile has no tip land", command=runner("periodic", "--clearances", "1.7e-3", "4.2e-3", "2.1e-3")),
    BadInput("cases.run.mesh-tolerance", ("--mesh-tolerance 0.01", "0 < tolerance < 1e-3"),
             why="a mesh coarser than the particles", command=runner("periodic", "--mesh-tolerance", "0.01")),
    BadInput("cases.run.out-is-a-file", ("--out", "is a file"),
             why="the run directory must be a directory", files={"afile": "x\n"},
             command=[*RUNNER, "periodic", "--out", "{tmp}/afile"], intact=("afile",)),
    BadInput("cases.run.feed-at", ("--feed-at element:99", "1 <= N <= 8"),
             why="the feed must be at the inlet or at an element of the barrel",
             command=runner("nonperiodic", "--feed-at", "element:99")),
    BadInput("cases.run.lmp-missing", ("lmp executable not found", "TSG_LMP=/nonexistent/lmp"),
             why="a wrong TSG_LMP is found before the 12 s fill, not after it",
             command=runner("periodic"), env={"TSG_LMP": "/nonexistent/lmp"}),
    BadInput("cases.run.lmp-not-executable", ("not executable", "TSG_LMP={root}/README.md"),
             why="an lmp that cannot be started", command=runner("periodic"), env={"TSG_LMP": str(ROOT / "README.md")}),
    BadInput("cases.run.mpirun-missing", ("mpirun not found", "1 rank"),
             why="several ranks need mpirun", command=runner("periodic", "--np", "2"),
             env={"TSG_MPIEXEC": "/nonexistent/mpirun"}),
    # values no run can mean: refused by the runner before the fill and by LIGGGHTS from the same lines
    *refused("periodic", "rpm", -600, ("> 0", "screw_direction -1"),
             "a negative speed turned the screws backwards silently"),
    *refused("periodic", "rpm", 0, ("> 0",), "0 rpm divided by zero in a stock message"),
    *refused("periodic", "screw_direction", 0, ("use 1", "or -1"), "the screws turn forwards or backwards"),
    *refused("periodic", "dump_from", 100, ("only with dump_every >= 1",), "dumps from a step, but no dumps asked for"),
    *refused("periodic", "gravity", -9.81, ("0 <= g <= 1000", "along -z"), "gravity points along -z; its sign is the input's"),
    *refused("full", "gravity", 2000, ("0 <= g <= 1000",), "no granulator runs at 200 g"),
    *refused("periodic", "stats_every", 0, (">= 1",), "a window of no steps (stock message before)"),
    *refused("periodic", "thermo_every", 0, (">= 1",), "every check runs at thermo steps"),
    *refused("periodic", "dump_every", -1, ("0 for no dumps",), "a negative dump interval"),
    *refused("periodic", "max_escaped", -1, (">= 0",), "a negative allowance"),
    *refused("periodic", "t_sample", -1, ("> 0",), "a negative sampling window (stock message before)"),
    *refused("periodic", "t_startup", -0.1, (">= 0",), "a negative start-up"),
    *refused("periodic", "buffer", 0.05, ("domain_length/2",), "buffers that cover the whole domain leave nothing to analyse"),
    *refused("periodic", "d_mean", 0, ("(0, 0.005)",), "particles of no size"),
    *refused("periodic", "rho_p", -1263, ("> 0",), "a negative density"),
    *refused("periodic", "G_p", 0, ("> 0",), "a zero modulus has no time step"),
    *refused("periodic", "nu_p", 0.5, ("(-1, 0.5)",), "Poisson's ratio 0.5 makes E/(1 - nu^2) meaningless for the Rayleigh step"),
    *refused("periodic", "e_pp", 0, ("(0, 1]",), "zero restitution has no damping coefficient"),
    *refused("periodic", "e_pg", 1.5, ("(0, 1]",), "restitution above 1 creates energy"),
    *refused("periodic", "mus_pg", -0.1, (">= 0",), "negative friction"),
    *refused("periodic", "mur_pp", -0.01, (">= 0",), "negative rolling friction"),
    *refused("periodic", "lambda_p", 1, ("[0, 1)",), "the EEPA time step scales with sqrt(1 - lambda_p)"),
    *refused("nonperiodic", "t_run", 0, ("> 0",), "a run of no time"),
    *refused("nonperiodic", "feed_rate_kg_h", 0, ("> 0",), "a feed that feeds nothing"),
    *refused("nonperiodic", "psd_sigma", 0.3, ("0.05 or 0.2",), "only the shipped size distributions have an include"),
    *refused("full", "steady_tolerance", 0, ("> 0",), "no run ever meets a zero imbalance"),
    *refused("full", "t_max_startup", -1, ("> 0",), "a negative start-up limit"),
    *refused("periodic", "write_state", 2, ("1 (state.restart", "or 0"), "a switch: any other value would write no state"),
    # runs from a kept state (cases/states.py): the state fixes the fill, its seed and the start-up
    BadInput("cases.run.from-state-missing", ("--from-state {tmp}/nowhere", "no state.json"),
             why="a state directory without its description cannot be checked against the case",
             command=runner("periodic", "--from-state", "{tmp}/nowhere")),
    BadInput("cases.run.from-state-other-scale", ("--from-state", "at demo scale", "not allowed", "at paper scale"),
             why="a demo state on the paper's machine would restart particles into other meshes",
             command=runner("periodic", "--scale", "paper", "--from-state", "{root}/cases/states/periodic-demo/seed-1")),
    BadInput("cases.run.from-state-seed", ("--seed 7 is not allowed with --from-state", "seed 1"),
             why="the state's fill has its own seed; another would describe a run that did not happen",
             command=runner("periodic", "--seed", "7", "--from-state", "{root}/cases/states/periodic-demo/seed-1")),
    BadInput("cases.run.from-state-startup", ("-v t_startup is not allowed with --from-state", "the state sets"),
             why="the start-up is the state's: another t_startup would not apply",
             command=runner("periodic", "-v", "t_startup", "0.2", "--from-state", "{root}/cases/states/periodic-demo/seed-1")),
    BadInput("cases.run.from-state-holdup", ("--holdup-g is not allowed with --from-state", "fill and machine"),
             why="the hold-up is the state's fill",
             command=runner("periodic", "--holdup-g", "3", "--from-state", "{root}/cases/states/periodic-demo/seed-1")),
    BadInput("cases.run.from-state-model", ("-v cohesion 1 is not allowed with --from-state", "made with cohesion 0",
                                            "contact history"),
             why="the restart file keeps the cohesionless model's contact history; LIGGGHTS stops on another",
             command=runner("periodic", "-v", "cohesion", "1", "--from-state", "{root}/cases/states/periodic-demo/seed-1")),
    *refused("full", "inside_records", 2, ("1 (a record per particle", "or 0"), "a switch: any other value would write no snapshot"),
]
