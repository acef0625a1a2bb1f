"""Kept states: a periodic run's state at the end of its start-up, kept (compressed, in git) so that
other runs start from it instead of running the start-up again.

    python -m tsg_cases.states keep RUN_DIR STATE_DIR     # after tsg-run-case periodic ... -v write_state 1
    python -m tsg_cases.states keep RUN_DIR STATE_DIR --restart RUN_DIR/restart.STEP   # any restart of a run
    tsg-run-case periodic --scale demo --from-state STATE_DIR --out OUT [-v t_sample T]

A state directory holds state.restart.xz (the LIGGGHTS restart file the case wrote when its
start-up ended: `-v write_state 1`), fill.vars (the fill's smallest diameter and particle count, which
a continued run reads) and state.json: the case, scale, fill seed and start-up time of the run that
made it, the simulation time its restart file carries, its model (MODEL_VARIABLES), its command and
commit. A run from a state is the same case with the same fill, continued: `start restart` from that
file with `t_startup` the state's, so its measurements begin where the state ends
(cases/in.tsg_periodic, "job segments"), at the state's time step or another (the case plans its
phases in time, from the time the restart file carries). The restart file is read by the
lmp of today: a change to a fix's restart layout needs the states made again (the command is in
state.json); so does a state made before restart files carried their simulation time (no "time" in
state.json), whose time a continuation could only guess as step x dt.
"""
from __future__ import annotations

import argparse
import json
import lzma
import math
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

from tsg_analysis.liggghts_log import parse_thermo
from tsg_analysis.run_files import log_segment_files

STATE_RESTART = "state.restart"  # the file `-v write_state 1` writes in the run directory
# variables that choose the contact model and the wall fix: a restart file keeps their per-contact
# history, and LIGGGHTS refuses to continue it with another ("saved simulation state used different
# contact history model"); a run from a state uses the state's (the case's defaults when not given)
MODEL_VARIABLES = {"cohesion": "0", "screw_drive": "corotating"}
DESCRIPTION = "state.json"
FILL_VARS = "fill.vars"


class StateError(Exception):
    """A state directory that cannot be used (one line naming the file and what is wrong)."""


@dataclass(frozen=True)
class KeptState:
    path: Path
    case: str
    scale: str
    seed: int
    t_startup: float  # s: the run's start-up, at whose end the state was written
    step: int
    time: float  # s: the simulation time at `step`, stored in the restart file
    model: dict[str, str]  # MODEL_VARIABLES as the state was made
    command: str
    commit: str | None

    @property
    def restart(self) -> Path:
        return self.path / f"{STATE_RESTART}.xz"


def read(state_dir: Path) -> KeptState:
    """The state in `state_dir`, checked: its description, restart file and fill variables."""
    description = state_dir / DESCRIPTION
    try:
        values = json.loads(description.read_text())
    except FileNotFoundError:
        raise StateError(f"--from-state {state_dir}: no {DESCRIPTION} (a kept state: python -m tsg_cases.states keep)") from None
    except json.JSONDecodeError as problem:
        raise StateError(f"--from-state {state_dir}: {DESCRIPTION} is not JSON ({problem})") from None
    for name in (f"{STATE_RESTART}.xz", FILL_VARS):
        if not (state_dir / name).is_file():
            raise StateError(f"--from-state {state_dir}: {name} is missing")
    if isinstance(values, dict) and "time" not in values:
        raise StateError(f"--from-state {state_dir}: made before restart files carried their simulation time (no \"time\" in "
                         f"{DESCRIPTION}); make it again with today's lmp: {values.get('command', 'see cases/states.py')}")
    try:
        return KeptState(state_dir, str(values["case"]), str(values["scale"]), int(values["seed"]),
                         float(values["t_startup"]), int(values["step"]), float(values["time"]),
                         {**MODEL_VARIABLES, **values.get("model", {})}, str(values["command"]), values.get("commit"))
    except (KeyError, TypeError, ValueError) as problem:
        raise StateError(f"--from-state {state_dir}: {DESCRIPTION} lacks or mistypes {problem}") from None


def unpack(state: KeptState, out: Path) -> Path:
    """The state's restart file and fill variables into the run directory `out`; the restart file's path."""
    restart = out / STATE_RESTART
    with lzma.open(state.restart) as packed, open(restart, "wb") as unpacked:
        shutil.copyfileobj(packed, unpacked)
    shutil.copyfile(state.path / FILL_VARS, out / FILL_VARS)
    return restart


def _restart_row(run_dir: Path, t_startup: float) -> tuple[int, float]:
    """The step and time the state was written at: the thermo row at the end of the start-up (the
    case writes state.restart right after its start-up run, which ends on a thermo row)."""
    rows = [(int(step), float(time)) for block in parse_thermo((run_dir / "log.lammps").read_text(errors="replace"))
            for step, time in zip(block["Step"], block["Time"])]
    at_end = [(step, time) for step, time in rows if math.isclose(time, t_startup, rel_tol=1e-5)]
    if not at_end:
        raise StateError(f"{run_dir / 'log.lammps'}: no thermo row at the end of the start-up, t_startup = {t_startup:g} s")
    return at_end[0]


def _row_at_step(run_dir: Path, step: int) -> float:
    """The time of the thermo row at `step` in the run's logs (a kept run's segments: log.upto-*.lammps)."""
    for log in log_segment_files(run_dir):
        for block in parse_thermo(log.read_text(errors="replace")):
            for row_step, time in zip(block["Step"], block["Time"]):
                if int(row_step) == step:
                    return float(time)
    raise StateError(f"{run_dir}: no thermo row at step {step} in its logs (log*.lammps): a restart file's step "
                     f"must be a multiple of thermo_every")


def keep(run_dir: Path, state_dir: Path, restart: Path | None = None) -> KeptState:
    """Compress the state a run wrote (-v write_state 1) into `state_dir`, with its description; or, with
    `restart`, one of the run's restart files (restart.STEP, e.g. a kept run's, in its sampling window):
    the state's start-up then ends at that file's time."""
    from_file = restart is not None
    if restart is None:
        restart = run_dir / STATE_RESTART
        if not restart.is_file():
            raise StateError(f"{run_dir}: no {STATE_RESTART} (run the case with -v write_state 1)")
    elif not restart.is_file() or not restart.name.startswith("restart.") or not restart.suffix[1:].isdigit():
        raise StateError(f"--restart {restart}: not a restart file restart.STEP of the run")
    params = json.loads((run_dir / "params.json").read_text())
    if params["case"] != "periodic":
        raise StateError(f"{run_dir}: a {params['case']} run; kept states are periodic runs")
    state_dir.mkdir(parents=True, exist_ok=True)
    with open(restart, "rb") as plain, lzma.open(state_dir / f"{STATE_RESTART}.xz", "wb", preset=6) as packed:
        shutil.copyfileobj(plain, packed)
    shutil.copyfile(run_dir / FILL_VARS, state_dir / FILL_VARS)
    variables = params["variables"]
    model = "".join(f" -v {name} {variables[name]}" for name in MODEL_VARIABLES if name in variables)
    if from_file:
        step = int(restart.suffix[1:])
        time = t_startup = _row_at_step(run_dir, step)
        # a run prepared by a job chain (cases/slurm/segment.sh) names its own options, --holdup-g or
        # --clearances among them, which params.json does not keep
        chain = run_dir / "prepared-with"
        if chain.is_file():
            made = f"tsg-run-case periodic {chain.read_text().strip()} --out RUN"
        else:
            given = "".join(f" -v {name} {value}" for name, value in variables.items()
                            if name not in ("case_dir", "out_dir", "mesh_dir", "fill_file", "zones_file"))
            made = (f"tsg-run-case periodic --scale {params['scale']} --seed {params['seed']} --np {params['np']} "
                    f"--out RUN{given}")
        command = (f"{made} (continued past step {step}); "
                   f"python -m tsg_cases.states keep RUN {state_dir} --restart RUN/{restart.name}")
    else:
        command = (f"tsg-run-case periodic --scale {params['scale']} --seed {params['seed']} --np {params['np']} "
                   f"--out RUN -v t_startup {variables['t_startup']} -v t_sample {variables['t_sample']} -v write_state 1{model}; "
                   f"python -m tsg_cases.states keep RUN {state_dir}")
        t_startup = float(variables["t_startup"])
        step, time = _restart_row(run_dir, t_startup)
    description = {"case": params["case"], "scale": params["scale"], "seed": params["seed"],
                   "t_startup": t_startup, "step": step, "time": time,
                   "model": {name: str(variables.get(name, default)) for name, default in MODEL_VARIABLES.items()},
                   "command": command, "commit": params.get("git_commit")}
    (state_dir / DESCRIPTION).write_text(json.dumps(description, indent=1) + "\n")
    return read(state_dir)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tsg_cases.states", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(dest="command", required=True)
    keeping = commands.add_parser("keep", help="compress a run's state.restart into a state directory")
    keeping.add_argument("run_dir", type=Path)
    keeping.add_argument("state_dir", type=Path)
    keeping.add_argument("--restart", type=Path, help="one of the run's restart files (restart.STEP) instead of the "
                         "state.restart its start-up wrote: the state then ends at that file's time")
    args = parser.parse_args(argv)
    try:
        state = keep(args.run_dir, args.state_dir, args.restart)
    except StateError as problem:
        print(f"python -m tsg_cases.states: {problem}", file=sys.stderr)
        return 1
    print(f"kept {state.case} {state.scale} seed {state.seed} at t = {state.t_startup:g} s (step {state.step}) in "
          f"{state.path} ({state.restart.stat().st_size / 1e6:.2f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
