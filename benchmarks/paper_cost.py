"""Cost of the paper-scale (400 um) periodic case in motion: this build against a baseline lmp,
side by side in one invocation.

    .venv/bin/python benchmarks/paper_cost.py --baseline-lmp /work/lmp-main/lmp [--np 1 2] [--steps 400]
        [--repeat 1] [--startup-steps N] [--restart FILE] [--work DIR] [--callgrind-steps 0]

1. Prepare (once per --work directory): cases/run_case.py periodic --scale paper with no steps:
   the 1 um meshes, the zones and the static fill (63 320 particles of 400 um, 2.7 g).
2. Motion restart (once per --work directory, this build): the case runs from the fill for 0.1 s of
   simulated time (--startup-steps to choose; screws turning, particles dragged along and squeezed:
   a state in motion, about 200 000 steps, about an hour on 2 cores) and writes a restart file
   (tens of MB: kept out of git, made here); --restart takes a later one (e.g. a kept run's). The
   demo scale instead starts, unless --startup-steps or --restart is given, from its kept steady
   state (cases/states/periodic-demo/seed-1, t = 1.5 s after the fill): a cost measured in motion,
   not in the first milliseconds after the fill.
3. Each lmp (baseline, this build; alternated, --repeat times, for each --np) reads the restart and
   runs --steps steps of the case as it is: cases/include models, corotating screws and fixed
   barrel, guards (fix check/contact), measurement fixes (element statistics, mass flow,
   residence time), thermo every --thermo-every steps, with the variables of the prepared run (its
   lmp.vars: the values it ran with) over the defaults of cases/in.tsg_periodic.
Printed per run: LIGGGHTS' loop time, its breakdown (pair, neighbour lists, comm, output, fixes),
the corotating fix's own contact time, particle-steps per second per core and core-hours per
simulated second; then the ratio baseline / this build. With --callgrind-steps N it also counts
the instructions of N steps' run loop (valgrind --tool=callgrind, serial), which do not depend on
the machine's load. Records the machine (CPU model, cores, load), the commit and the command.
A baseline built before the restart files carried the simulation time (b9673fc) reads a copy
without it: --restart-without-time (both variants read that copy).
Not a test: wall-clock numbers depend on the machine and its load.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import re
import shlex
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from tsg_analysis.liggghts_log import parse_thermo
from tsg_cases import states
from tsg_cases.case_parameters import case_input, index_lines
from tsg_cases.prepared import domain_length
from tsg_cases.run_case import SCALES, UserError, read_lmp_vars

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
# The start-up before the restart in motion at the paper scale: 0.1 s of simulated time from the fill
# (issue: a cost in motion, the screws engaged; the first milliseconds after the fill cost a third).
PAPER_STARTUP_S = 0.1
DEMO_STATE = CASES / "states" / "periodic-demo" / "seed-1"   # the demo's default start: steady, t = 1.5 s
# The guards stay on (their per-step cost is part of the case) but out of reach: the static paper
# fill trips max_speed within a few steps (a particle touching a screw at phase 0; docs/stability.md).
# The demo scale keeps the case's guards.
RELAXED_GUARDS = {"guard_max_speed": 1e9, "guard_max_pair_overlap": 1e9, "guard_max_wall_overlap": 1e9}

BENCH_INPUT = """# benchmarks/paper_cost.py: the paper-scale periodic case continued from a restart taken in motion
# (the lines of cases/in.tsg_periodic after the fill, with read_restart in place of domain.in + fill)
processors ${procs_x} 1 1
read_restart ${restart_file}
${case_defaults}
include ${case_dir}/include/balance.in
include ${mesh_dir}/machine.in
newton off
communicate single vel yes
variable d_min equal ${d_min_value}
include ${case_dir}/include/materials.in
include ${case_dir}/include/models.in
include ${case_dir}/include/geometry.in
fix integrate all nve/sphere
fix gravity all gravity ${gravity} vector 0 0 -1
include ${case_dir}/include/timestep.in
variable analysis_lo equal ${x_lo}+${buffer}
variable analysis_hi equal ${x_lo}+${domain_length}-${buffer}
variable sensor_1 equal ${analysis_lo}
variable sensor_2 equal ${analysis_hi}
fix residence all residence/time zones ${zones_file} records ${out_dir}/residence.txt &
    periodic ${analysis_lo} analysis ${analysis_lo} ${analysis_hi}
include ${case_dir}/include/element_stats.in
include ${case_dir}/include/massflow.in
variable thermo_measures equal 1
include ${case_dir}/include/thermo.in
# one thermo interval first, so that the timed run below has no set-up in it (neighbour lists, the
# screws' triangles and trees, the fixes' set-up); a profiler is switched on between the two
run ${thermo_every} post no
variable perf_on index 0           # 1: perf's control FIFO is ${perf_control}
if "${perf_on} == 1" then "shell echo enable > ${perf_control}"
run ${bench_steps} pre no
"""

RESTART_INPUT = """# benchmarks/paper_cost.py: start-up of the paper-scale periodic case, then a restart in motion
variable restart_file index restart.bin   # declared before check_variables in the case
include ${case_dir}/in.tsg_periodic
# the restart step a multiple of thermo_every: a baseline lmp of an earlier commit computes
# fix check/contact only at multiples of its interval, and its thermo at the first step needs it
run $(ceil(step/v_thermo_every)*v_thermo_every) upto
# the measurement fixes' state stays out: their restart format changes between versions, and each
# benchmark run starts them afresh (a baseline lmp of an earlier commit can read the file); the
# thermo line that reads them goes first (write_restart initialises the run state, thermo included)
thermo_style custom step atoms
unfix residence
unfix element_stats
unfix massflow
write_restart ${restart_file}
"""


@dataclass
class Result:
    label: str
    np: int
    steps: int
    atoms: int
    loop_s: float
    breakdown: dict[str, float]   # share of the loop time, %
    fix_ms: float                 # corotating fix's own contact handling, ms/step (slowest rank)
    dt: float
    neighbours_per_particle: float = float("nan")   # pair neighbours per particle at the end of the run
    neighbour_builds: int = -1                        # neighbour-list builds during the run
    time_s: float = float("nan")                      # simulated time at the timed run's start, s

    @property
    def core_s_per_step(self) -> float:
        return self.loop_s * self.np / self.steps

    @property
    def particle_steps_per_core_s(self) -> float:
        return self.atoms / self.core_s_per_step

    @property
    def core_hours_per_sim_s(self) -> float:
        return self.core_s_per_step / self.dt / 3600.0


def mpi(lmp: str, np_ranks: int) -> list[str]:
    if np_ranks <= 1:
        return [lmp]
    return ["mpirun", "-np", str(np_ranks), "--oversubscribe", "--allow-run-as-root", "--bind-to", "none", lmp]


def lmp_run(command: list[str], workdir: Path, variables: dict[str, object]) -> str:
    for name, value in variables.items():
        command += ["-var", name, str(value)]
    done = subprocess.run(command, cwd=workdir, capture_output=True, text=True, errors="replace",
                          env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    log = (workdir / "log.lammps").read_text(errors="replace") if (workdir / "log.lammps").exists() else ""
    if done.returncode != 0:
        raise SystemExit(f"lmp failed in {workdir} (exit {done.returncode}):\n{done.stdout[-3000:]}\n{done.stderr[-2000:]}")
    return log


def case_defaults() -> str:
    """The `variable NAME index DEFAULT` lines of cases/in.tsg_periodic, for the benchmark input: the
    case's own defaults of every variable that the prepared run and the benchmark do not set (a value
    given with -var wins over an index line, as it does in the case)."""
    return "\n".join(index_lines(case_input("periodic")))


# Variables of a prepared run that belong to its own run directory and schedule, not to the physics
# or the measurements that the benchmark times: the benchmark sets its own.
RUN_OWN = {"case_dir", "out_dir", "fill_file", "start", "restart_file", "t_startup", "t_sample", "write_state",
           "restart_every", "thermo_every", "stats_every", "dump_every", "dump_from", "snapshot", "procs_x",
           "mesh_dir", "zones_file", "domain_length"}


def stale_variables(prepared: Path, scale: str) -> str:
    """The variables of the scale (run_case.SCALES) that a prepared run holds with other values or
    lacks, e.g. "skin_fraction (none, not 0.2)"; empty when none, or when nothing is prepared yet."""
    if not (prepared / "lmp.vars").is_file():
        return ""
    held = read_lmp_vars(prepared)
    wanted = {name: str(value) for name, value in SCALES[scale]["vars"].items() if name not in RUN_OWN}
    return ", ".join(f"{name} ({held.get(name, 'none')}, not {value})" for name, value in wanted.items()
                     if name not in held or float(held[name]) != float(value))


def prepare(work: Path, lmp: str, scale: str = "paper") -> dict[str, object]:
    """Meshes, zones and fill of the scale (run_case.py with no steps); the case variables: the
    prepared run's lmp.vars (the values it ran with; `--work DIR` with DIR/prepared a link to a run
    directory times that run's settings), less those of RUN_OWN."""
    prepared = work / ("prepared" if scale == "paper" else f"prepared-{scale}")
    stale = stale_variables(prepared, scale)
    if stale and not prepared.is_symlink():   # prepared here by an older tree: prepared again
        print(f"paper_cost.py: {prepared} was prepared with {stale}, not the {scale} scale's values of today: "
              "preparing it again", file=sys.stderr)
        shutil.rmtree(prepared)
    if not (prepared / "fill.in").exists():
        done = subprocess.run([sys.executable, str(CASES / "run_case.py"), "periodic", "--scale", scale, "--out",
                               str(prepared), "-v", "t_startup", "0", "-v", "t_sample", "1e-12"],
                              capture_output=True, text=True, env=dict(os.environ, TSG_LMP=lmp))
        if done.returncode != 0:
            raise SystemExit(f"paper_cost.py: preparing {prepared} failed (exit {done.returncode}):\n"
                             f"{done.stdout[-2000:]}\n{done.stderr[-2000:]}")
    log = (prepared / "log.lammps").read_text(errors="replace")
    fill = (prepared / "fill.in").read_text()
    try:
        run_variables = {k: v for k, v in read_lmp_vars(prepared).items() if k not in RUN_OWN}
    except UserError as error:
        raise SystemExit(f"paper_cost.py: {error}") from None
    mesh_dir = Path(re.search(r"mesh_dir=(\S+)", log).group(1))
    if not mesh_dir.is_dir():  # prepared in another checkout: the same meshes of this one
        mesh_dir = ROOT / "build" / "meshes" / mesh_dir.name
    # the run's own domain length (the meshes' zones.txt, as tsg-run-case passes it): the mass-flow
    # sensors a restart file holds are at its planes
    return {"mesh_dir": mesh_dir, "zones_file": prepared / "zones.txt", "domain_length": repr(domain_length(mesh_dir)),
            "fill_file": prepared / "fill.in", "scale": scale,
            "run_variables": run_variables,
            "d_min_value": fill_d_min(fill, prepared / "fill.in"),
            "dt": float(re.search(r"time step (\S+) s", log).group(1))}


def make_restart(work: Path, lmp: str, case: dict[str, object], startup_steps: int, thermo_every: int) -> Path:
    restart = work / (f"motion-{startup_steps}.restart" if case["scale"] == "paper"
                      else f"motion-{case['scale']}-{startup_steps}.restart")
    if restart.exists():
        return restart
    run_dir = work / f"startup-{case['scale']}-{startup_steps}"
    run_dir.mkdir(parents=True, exist_ok=True)
    (run_dir / "in.restart").write_text(RESTART_INPUT)
    dt = float(case["dt"])
    thermo_every = max(thermo_every, 1000)   # the case runs in chunks of thermo_every steps, each with a set-up
    variables = {**case["run_variables"],   # the benchmark's own values below win, as in bench()
                 "case_dir": CASES, "out_dir": run_dir, "restart_file": restart, "t_startup": startup_steps * dt,
                 "t_sample": 1e-12, "thermo_every": thermo_every, "stats_every": thermo_every, **guards(case),
                 **{k: case[k] for k in ("mesh_dir", "zones_file", "fill_file", "domain_length")}}
    print(f"[restart] {startup_steps} steps ({1e3 * startup_steps * dt:.1f} ms) from the fill, 2 ranks ...", flush=True)
    lmp_run(mpi(lmp, 2) + ["-in", "in.restart", "-log", "log.lammps", "-echo", "none"], run_dir, variables)
    return restart


def fill_d_min(text: str, where: Path) -> str:
    """The smallest diameter a fill file (fill.in, fill.vars) declares, as written."""
    d_min = re.search(r"variable d_min equal (\S+)", text)
    if d_min is None:
        raise SystemExit(f"{where}: no 'variable d_min equal'")
    return d_min.group(1)


def demo_state_restart(work: Path, case: dict[str, object]) -> Path:
    """The demo's kept steady state (DEMO_STATE), unpacked into `work`; its fill's smallest diameter
    goes into `case` (the state's fill, not the prepared one)."""
    state = states.read(DEMO_STATE)
    unpacked = work / f"demo-state-seed-{state.seed}"
    unpacked.mkdir(parents=True, exist_ok=True)
    restart = unpacked / states.STATE_RESTART
    if not restart.exists():
        states.unpack(state, unpacked)
    case["d_min_value"] = fill_d_min((unpacked / states.FILL_VARS).read_text(), DEMO_STATE / states.FILL_VARS)
    print(f"[restart] the demo's kept steady state {DEMO_STATE} (fill seed {state.seed}, t = {state.time:g} s, "
          f"step {state.step})", flush=True)
    return restart


def motion_restart(work: Path, lmp: str, case: dict[str, object], startup_steps: int | None, thermo_every: int) -> Path:
    """The state a benchmark starts from: at the demo scale its kept steady state, at the paper scale
    the case run PAPER_STARTUP_S from the fill; --startup-steps given: that many steps from the fill."""
    if case["scale"] == "demo" and startup_steps is None:
        return demo_state_restart(work, case)
    steps = startup_steps or math.ceil(PAPER_STARTUP_S / float(case["dt"]))
    return make_restart(work, lmp, case, steps, thermo_every)


def restart_without_time(restart: Path, work: Path) -> Path:
    """A copy of the restart file without the simulation-time entry of its header (the flag that
    src-liggghts-eepa/patches/write-restart-cpp.patch adds after YZ, with its double), which an lmp
    built before that patch (e.g. b9673fc) rejects as an invalid flag. Both variants then read the
    same file; the fixes keep their own clocks in their restart data, so the physics is the same."""
    source = (ROOT / "build" / "liggghts" / "src" / "write_restart.cpp").read_text()
    names = re.search(r"enum\{VERSION,(.*?)\};", source, re.S)
    if names is None or "ATIME" not in names.group(1):
        raise SystemExit("--restart-without-time: build/liggghts/src/write_restart.cpp has no ATIME header entry")
    flags = ["VERSION"] + [n.strip() for n in re.sub(r"//[^\n]*", "", names.group(1)).split(",") if n.strip()]
    key = struct.pack("<i", flags.index("ATIME"))
    data = restart.read_bytes()
    end = struct.pack("<i", -1)
    for match in re.finditer(re.escape(key), data[:1 << 16]):   # the header is the file's first few kB
        at = match.start()
        if data[at + 12:at + 16] == end:          # flag, the time (a double), then the header's end mark
            stripped = work / (restart.name + ".without-time")
            stripped.write_bytes(data[:at] + data[at + 12:])
            return stripped
    raise SystemExit(f"--restart-without-time: no time entry found in the header of {restart}")


def guards(case: dict[str, object]) -> dict[str, object]:
    return RELAXED_GUARDS if case["scale"] == "paper" else {}


def parse(label: str, np_ranks: int, log: str, dt: float) -> Result:
    loop = re.findall(r"Loop time of (\S+) on \d+ procs for (\d+) steps with (\d+) atoms", log)[-1]
    shares = {}
    for name in ("Pair", "Neigh", "Comm", "Outpt", "Other"):  # LIGGGHTS 3.8 counts fixes in Other
        found = re.findall(rf"^{name}\s+time \(%\) = \S+ \((\S+)\)", log, re.M)
        shares[name] = float(found[-1]) if found else float("nan")
    fix = re.findall(r"contact handling (\S+) ms/step", log)
    neighbours = re.findall(r"^Ave neighs/atom = (\S+)", log, re.M)
    builds = re.findall(r"^Neighbor list builds = (\d+)", log, re.M)
    timed = [block for block in parse_thermo(log) if "Time" in block and len(block["Time"])][-1:]
    return Result(label, np_ranks, int(loop[1]), int(loop[2]), float(loop[0]), shares,
                  float(fix[-1]) if fix else float("nan"), dt,
                  float(neighbours[-1]) if neighbours else float("nan"), int(builds[-1]) if builds else -1,
                  float(timed[0]["Time"][0]) if timed else float("nan"))


def bench(label: str, lmp: str, np_ranks: int, restart: Path, case: dict[str, object], steps: int, thermo_every: int,
          workdir: Path, wrapper: list[str] | None = None, extra: dict[str, str] | None = None) -> tuple[Result, str]:
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / "in.bench").write_text(BENCH_INPUT.replace("${case_defaults}", case_defaults()))
    variables = {**case["run_variables"],
                 "case_dir": CASES, "out_dir": workdir, "restart_file": restart, "bench_steps": steps,
                 "thermo_every": thermo_every, "stats_every": thermo_every, "procs_x": "*", "dump_every": 0,
                 **guards(case),
                 **{k: case[k] for k in ("mesh_dir", "zones_file", "d_min_value", "domain_length")}, **(extra or {})}
    command = (wrapper or []) + mpi(lmp, np_ranks) + ["-in", "in.bench", "-log", "log.lammps", "-echo", "none"]
    log = lmp_run(command, workdir, variables)
    return parse(label, np_ranks, log, float(case["dt"])), log


def callgrind_instructions(label: str, lmp: str, restart: Path, case: dict[str, object], steps: int, workdir: Path,
                           extra: dict[str, str]) -> int:
    out = workdir / "callgrind.out"
    wrapper = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", "--collect-atstart=no",
               "--toggle-collect=LAMMPS_NS::Verlet::run(int)"]
    # the input's first run (one thermo interval, here `steps`) and the timed run are both in
    # Verlet::run: half the count is the timed run's, within the difference of the two states
    bench(label, lmp, 1, restart, case, steps, steps, workdir, wrapper, extra)
    summary = re.search(r"^summary:\s+(\d+)", out.read_text(errors="replace"), re.M)
    return int(summary.group(1)) // 2


def perf_profile(label: str, lmp: str, np_ranks: int, restart: Path, case: dict[str, object], steps: int,
                 thermo_every: int, workdir: Path, extra: dict[str, str]) -> str:
    """Shares of CPU samples by function (perf record -e cpu-clock, all ranks) of the timed run only:
    perf starts disabled and the input switches it on after the set-up and the first thermo interval
    (perf's control FIFO, written by the input's shell command on rank 0)."""
    workdir.mkdir(parents=True, exist_ok=True)
    out, control = workdir / "perf.data", workdir / "perf-control.fifo"
    control.unlink(missing_ok=True)
    os.mkfifo(control)
    wrapper = ["perf", "record", "-q", "-F", "499", "-e", "cpu-clock", "-D", "-1", "--control", f"fifo:{control}",
               "-o", str(out), "--"]
    bench(label, lmp, np_ranks, restart, case, steps, thermo_every, workdir, wrapper,
          {**extra, "perf_on": 1, "perf_control": str(control)})
    report = subprocess.run(["perf", "report", "--stdio", "-i", str(out), "--sort", "symbol", "--percent-limit", "0.7"],
                            capture_output=True, text=True).stdout
    return "\n".join(line for line in report.splitlines() if line.strip() and not line.startswith("#"))


def machine() -> str:
    model = "unknown CPU"
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            model = line.split(":", 1)[1].strip()
            break
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"], capture_output=True,
                           text=True).stdout.strip()
    load = " ".join(f"{v:.2f}" for v in os.getloadavg())
    return (f"{model}, {os.cpu_count()} cores, load average {load}, {platform.node()}; commit {commit}"
            f"{' (uncommitted changes)' if dirty else ''}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--baseline-lmp", required=True, help="the lmp to compare with (e.g. a copy of main's)")
    parser.add_argument("--lmp", default=os.environ.get("TSG_LMP", str(ROOT / "build" / "lmp")), help="this build's lmp")
    parser.add_argument("--np", type=int, nargs="+", default=[1, 2], help="MPI ranks (each measured)")
    parser.add_argument("--steps", type=int, default=400)
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--scale", choices=sorted(SCALES), default="paper",
                        help="the periodic case at the paper's 400 um or the demo's 1 mm (cases/run_case.py --scale)")
    parser.add_argument("--startup-steps", type=int, default=None,
                        help=f"steps from the fill before the restart (default at the paper scale: {PAPER_STARTUP_S} s "
                             f"of simulated time; the demo scale starts from its kept steady state unless this is given)")
    parser.add_argument("--restart", type=Path, default=None,
                        help="a restart in motion to use instead of making one (written without the measurement fixes)")
    parser.add_argument("--restart-without-time", action="store_true",
                        help="both variants read a copy of the restart without its simulation-time header entry "
                             "(for a baseline built before it, e.g. b9673fc)")
    parser.add_argument("--thermo-every", type=int, default=200)
    parser.add_argument("--callgrind-steps", type=int, default=0, help="also count instructions of N steps (serial)")
    parser.add_argument("--profile-steps", type=int, default=0,
                        help="also profile N steps with perf record (each variant, each --np)")
    parser.add_argument("--baseline-vars", nargs="*",
                        default=["squeeze_ledger=0", "neighbour_trigger=0", "skin_fraction=0.2"], metavar="NAME=VALUE",
                        help="case variables for the baseline only (default: the settings of main of b9673fc, the "
                             "speed target's reference: no squeeze ledger and the stock neighbour rule, which it "
                             "predates, and its neighbour skin of 0.2 d)")
    parser.add_argument("--this-vars", nargs="*", default=[], metavar="NAME=VALUE",
                        help="case variables for this build only, e.g. yield_pressure_pg=2.5e6 reset_contacts=1 "
                             "(the squeeze treatment from a restart written with the paper's model)")
    parser.add_argument("--work", type=Path, default=None, help="keeps the prepared fill and the restart between calls")
    parser.add_argument("--json", type=Path, default=None, help="also write every run and the summary here")
    parser.add_argument("--collect", action="store_true",
                        help="run nothing: read the runs an earlier invocation with the same options left in --work")
    args = parser.parse_args(argv)
    for option in ("lmp", "baseline_lmp"):  # every run changes directory: a path relative to here would not hold there
        path = Path(getattr(args, option)).resolve()
        if not (path.is_file() and os.access(path, os.X_OK)):
            parser.error(f"--{option.replace('_', '-')} {getattr(args, option)} is not allowed: an executable lmp "
                         f"({path} is not one)")
        setattr(args, option, str(path))
    if args.steps % args.thermo_every:  # the guards' fix is computed every thermo_every steps; thermo prints the last step
        parser.error(f"--steps {args.steps} is not allowed: a multiple of --thermo-every {args.thermo_every}")
    work = args.work or Path(tempfile.mkdtemp(prefix="paper_cost_"))
    work.mkdir(parents=True, exist_ok=True)
    print(f"command: {' '.join(shlex.quote(a) for a in [sys.executable] + sys.argv)}")
    machine_at_start = machine()
    print(f"machine: {machine_at_start}", flush=True)
    case = prepare(work, args.lmp, args.scale)
    restart = args.restart or motion_restart(work, args.lmp, case, args.startup_steps, args.thermo_every)
    if args.restart_without_time:
        restart = restart_without_time(restart, work)
    print(f"restart: {restart} ({restart.stat().st_size / 1e6:.0f} MB), time step {float(case['dt']):.4g} s", flush=True)
    variants = {"baseline": args.baseline_lmp, "this": args.lmp}
    extra = {"baseline": assignments(parser, args.baseline_vars), "this": assignments(parser, args.this_vars)}
    print(f"case variables of each variant: {extra}")
    results: dict[tuple[str, int], list[Result]] = {}
    print("wall-clock numbers below were measured on this machine under its current load (see load average)")
    print(f"{'run':<14}{'ranks':>6}{'atoms':>8}{'ms/step':>9}{'core-ms/step':>13}{'Mpart-steps/core-s':>20}"
          f"{'core-h/sim-s':>14}{'fix ms/step':>12}  pair/neigh/comm/outpt/other %")
    for repeat in range(args.repeat):
        for np_ranks in args.np:
            for label, lmp in variants.items():
                run_dir = work / f"{args.scale}-{label}-np{np_ranks}-{repeat}"
                if args.collect:   # a run of an earlier, interrupted invocation (its log), or none
                    log = (run_dir / "log.lammps").read_text(errors="replace") if (run_dir / "log.lammps").exists() else ""
                    if "Loop time" not in log:
                        continue
                    r = parse(label, np_ranks, log, float(case["dt"]))
                else:
                    r, _ = bench(label, lmp, np_ranks, restart, case, args.steps, args.thermo_every, run_dir,
                                 extra=extra[label])
                results.setdefault((label, np_ranks), []).append(r)
                shares = "/".join(f"{v:.1f}" for v in r.breakdown.values())
                print(f"{label + ' #' + str(repeat):<14}{np_ranks:>6}{r.atoms:>8}{1e3 * r.loop_s / r.steps:>9.3f}"
                      f"{1e3 * r.core_s_per_step:>13.3f}{r.particle_steps_per_core_s / 1e6:>20.3f}"
                      f"{r.core_hours_per_sim_s:>14.2f}{r.fix_ms:>12.3f}  {shares}", flush=True)
    summary = []
    for np_ranks in args.np if args.repeat > 0 else []:
        if ("baseline", np_ranks) not in results or ("this", np_ranks) not in results:
            continue
        base = [r.core_s_per_step for r in results[("baseline", np_ranks)]]
        mine = [r.core_s_per_step for r in results[("this", np_ranks)]]
        paired = [b / m for b, m in zip(base, mine)]   # each repeat ran the two back to back
        row = {"np": np_ranks, "baseline_ms_per_step": spread([1e3 * v / np_ranks for v in base]),
               "this_ms_per_step": spread([1e3 * v / np_ranks for v in mine]), "ratio_per_repeat": spread(paired),
               "ratio_of_best": min(base) / min(mine)}
        summary.append(row)
        print(f"{np_ranks} rank(s): core-seconds per step, baseline / this = {row['ratio_of_best']:.2f} (best of "
              f"{len(base)} and {len(mine)} runs); per repeat min/median/max {fmt(row['ratio_per_repeat'])} ({args.steps} steps, "
              f"machine load in the header)")
    counts: dict[str, int] = {}
    if args.callgrind_steps > 0:
        counts = {label: callgrind_instructions(label, lmp, restart, case, args.callgrind_steps, work / f"{args.scale}-callgrind-{label}",
                                                extra[label])
                  for label, lmp in variants.items()}
        for label, count in counts.items():
            print(f"callgrind {label:<9}: {count / args.callgrind_steps / 1e6:.1f} M instructions per step "
                  f"(run loop, serial, {args.callgrind_steps} steps)")
        print(f"callgrind: baseline / this = {counts['baseline'] / counts['this']:.2f} (instructions; independent of load)")
    if args.profile_steps > 0:
        for np_ranks in args.np:
            for label, lmp in variants.items():
                print(f"--- perf profile: {label}, {np_ranks} rank(s), {args.profile_steps} steps (CPU samples by function)")
                print(perf_profile(label, lmp, np_ranks, restart, case, args.profile_steps, args.thermo_every,
                                   work / f"{args.scale}-perf-{label}-np{np_ranks}", extra[label]), flush=True)
    machine_at_end = machine()
    print(f"machine at the end: {machine_at_end}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({
            "command": [sys.executable] + sys.argv, "machine_at_start": machine_at_start, "machine_at_end": machine_at_end,
            "scale": args.scale, "steps": args.steps, "repeat": args.repeat, "restart": str(restart),
            "lmp": {"baseline": args.baseline_lmp, "this": args.lmp}, "case_variables": extra,
            "time_step_s": float(case["dt"]),
            "runs": [{"label": r.label, "np": r.np, "steps": r.steps, "atoms": r.atoms, "loop_s": r.loop_s,
                      "ms_per_step": 1e3 * r.loop_s / r.steps, "core_ms_per_step": 1e3 * r.core_s_per_step,
                      "particle_steps_per_core_s": r.particle_steps_per_core_s,
                      "core_hours_per_sim_s": r.core_hours_per_sim_s, "fix_ms_per_step": r.fix_ms,
                      "neighbours_per_particle": r.neighbours_per_particle, "neighbour_builds": r.neighbour_builds,
                      "time_s": r.time_s,
                      "breakdown_percent": r.breakdown} for rs in results.values() for r in rs],
            "summary": summary,
            "collected": "runs read from the logs an earlier invocation left in --work (its command and machine are in "
                         "its own output)" if args.collect else None,
            "callgrind": {"steps": args.callgrind_steps, "instructions": counts} if counts else None}, indent=1) + "\n")
    return 0


def assignments(parser: argparse.ArgumentParser, words: list[str]) -> dict[str, str]:
    pairs = [w.split("=", 1) for w in words]
    bad = [w for w, p in zip(words, pairs) if len(p) != 2 or not p[0]]
    if bad:
        parser.error(f"{bad[0]!r} is not allowed: NAME=VALUE (a case variable)")
    return dict(pairs)


def spread(values: list[float]) -> dict[str, float]:
    return {"min": min(values), "median": statistics.median(values), "max": max(values), "n": len(values)}


def fmt(s: dict[str, float]) -> str:
    return f"{s['min']:.2f}/{s['median']:.2f}/{s['max']:.2f}"


if __name__ == "__main__":
    sys.exit(main())
