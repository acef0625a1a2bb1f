"""The accuracy-cost study tool's rows of the bad-input campaign (tests/errors/README.md): every row
stops before any run, in about a second."""
from __future__ import annotations

import json

from badinput import BadInput

ACCURACY = ["{python}", "-m", "tsg_cases.accuracy", "{tmp}/study"]
OTHER_RUN = json.dumps({"argv": ["periodic", "--scale", "demo", "--np", "1", "--seed", "1"], "state": "done"})

CASES: list[BadInput] = [
    BadInput("accuracy.ladder-setting", ("--ladder speed is not allowed", "use one of dt_fraction"),
             why="a setting the tool does not vary", command=[*ACCURACY, "--ladder", "speed", "1"]),
    BadInput("accuracy.ladder-dt", ("--ladder dt_fraction 0.5 is not allowed", "0 < value <= 0.3"),
             why="the case inputs refuse time steps above 0.3 of the Rayleigh time", command=[*ACCURACY, "--ladder", "dt_fraction", "0.5"]),
    BadInput("accuracy.ladder-empty", ("--ladder dt_fraction", "give at least one value"),
             why="a ladder without values", command=[*ACCURACY, "--ladder", "dt_fraction"]),
    BadInput("accuracy.ladder-guard", ("above the time-step guard", "guard_step_fraction = 0.2001"),
             why="the point would stop at its first step", command=[*ACCURACY, "--ladder", "dt_fraction", "0.3"]),
    BadInput("accuracy.ladder-reference", ("--ladder dt_fraction 0.2 is the reference's own setting",),
             why="it would rerun the reference", command=[*ACCURACY, "--ladder", "dt_fraction", "0.2"]),
    BadInput("accuracy.ladder-twice", ("given twice", "dt_fraction 0.15"),
             why="two run directories for one point", command=[*ACCURACY, "--ladder", "dt_fraction", "0.15", "0.15"]),
    BadInput("accuracy.sampling", ("--ladder sampling 1.5 is not allowed", "0 < value <= 1"),
             why="a fraction of the reference's window", command=[*ACCURACY, "--ladder", "sampling", "1.5"]),
    BadInput("accuracy.domain", ("--ladder domain box is not allowed", "periodic, nonperiodic, full"),
             why="not a case", command=[*ACCURACY, "--ladder", "domain", "box"]),
    BadInput("accuracy.replicas", ("--replicas 0 is not allowed", ">= 1"),
             why="no run per point", command=[*ACCURACY, "--replicas", "0", "--ladder", "np", "2"]),
    BadInput("accuracy.seed-with-replicas", ("--seed 7 is not allowed with --replicas 3", "1 ... 3"),
             why="the replicas' seeds are 1 ... R: a seed given beside them would be ignored",
             command=[*ACCURACY, "--replicas", "3", "--seed", "7", "--ladder", "np", "2"]),
    BadInput("accuracy.domain-var", ("--domain-var t_run", "no --ladder domain"),
             why="a variable that would be ignored", command=[*ACCURACY, "--ladder", "np", "2", "--domain-var", "t_run", "1"]),
    BadInput("accuracy.var", ("-v rmp", "did you mean rpm"),
             why="a misspelt variable would run every point with the default", command=[*ACCURACY, "-v", "rmp", "300"]),
    BadInput("accuracy.tolerance", ("--tolerance 5x is not allowed", "with % for relative"),
             why="not a tolerance", command=[*ACCURACY, "--ladder", "np", "2", "--tolerance", "5x"]),
    BadInput("accuracy.from-states-ladder", ("--ladder mesh_tolerance is not allowed with --from-states",
                                             "fix the fill and the machine", "dt_fraction, sampling, np"),
             why="a run from a kept state keeps the state's meshes and fill",
             command=[*ACCURACY, "--from-states", "{root}/cases/states/periodic-demo", "--ladder", "mesh_tolerance", "2e-5"]),
    BadInput("accuracy.other-options", ("was run with other options", "remove it or use another study directory"),
             why="a finished point of another reference must not be reused as this one's",
             files={"study/reference/point.json": OTHER_RUN}, intact=("study/reference/point.json",),
             command=[*ACCURACY, "--ladder", "np", "2"]),
]
