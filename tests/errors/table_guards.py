"""Bad input to the guards of fix check/contact (docs/stability.md)."""
from __future__ import annotations

from badinput import BadInput
from crafted_scenes import RANK_ONE_GUARDS

SCENE = """units si
atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box
create_box 1 box
fix m1 all property/global youngsModulus peratomtype 5.0e7
fix m2 all property/global poissonsRatio peratomtype 0.25
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
create_atoms 1 single 0 0 0 units box
set atom * diameter 0.002 density 2500
fix integr all nve/sphere
timestep 1e-6
"""


def check_contact(arguments: str) -> str:
    return SCENE + f"fix check all check/contact {arguments}\nrun 10\n"


CASES: list[BadInput] = [
    BadInput("guards.max-speed-negative", ("max_speed = -1", "outside the allowed range (0, inf) m/s"),
             why="a speed bound must be a positive speed; 0 or less would stop every run",
             lmp_input=check_contact("max_speed -1")),
    BadInput("guards.fast-speed-not-below-max-speed", ("fast_speed = 8 m/s must be below max_speed = 5 m/s",),
             why="events are counted between the two speeds; above max_speed the run has stopped already",
             lmp_input=check_contact("max_speed 5 fast_speed 8")),
    BadInput("guards.max-wall-overlap-zero", ("max_wall_overlap = 0", "outside the allowed range (0, inf)"),
             why="an overlap bound of 0 would stop at the first wall contact",
             lmp_input=check_contact("walls walls max_wall_overlap 0")),
    BadInput("guards.max-pair-overlap-not-a-number", ("max_pair_overlap = 0.5x", "is not a number"),
             why="a bound with trailing text is a typo, not a number to round",
             lmp_input=check_contact("max_pair_overlap 0.5x")),
    BadInput("guards.pair-every-zero", ("pair_every = 0", "must be a positive integer"),
             why="a pair-overlap check every 0 steps is not an interval",
             lmp_input=check_contact("pair_every 0")),
    BadInput("guards.step-fraction-above-one", ("step_fraction = 2", "outside the allowed range (0, 1]"),
             why="a time step above the critical estimate is never stable; use action warn to run beyond 0.2",
             lmp_input=check_contact("step_fraction 2")),
    BadInput("guards.action-unknown", ("action = stop", "must be 'error' or 'warn'"),
             why="only two reactions to a time step above the fraction exist",
             lmp_input=check_contact("action stop")),
    BadInput("guards.wall-overlap-without-walls", ("max_wall_overlap needs 'walls",),
             why="the wall-overlap bound needs the wall fix whose meshes it watches",
             lmp_input=check_contact("max_wall_overlap 0.5")),
    BadInput("guards.walls-not-a-mesh-wall", ("walls = nowall", "is not the ID of a fix wall/gran"),
             why="the monitor reads the meshes of a wall/gran or wall/gran/corotating fix",
             lmp_input=check_contact("walls nowall")),
    BadInput("guards.unknown-keyword", ("unknown keyword 'max_force'", "allowed: every, pair_every, step_fraction"),
             why="a misspelt guard would silently be off",
             lmp_input=check_contact("max_force 1")),
    BadInput("guards.time-step-too-large", ("time step 0.0001 s is 2.61 of the critical step estimate",
                                            "above the allowed step_fraction 0.2"),
             why="a time step above the safe fraction of the Rayleigh estimate is an error unless action warn",
             lmp_input=check_contact("every 10").replace("timestep 1e-6", "timestep 1e-4")),
]

# A guard that only rank 1 sees, on 2 ranks of a run periodic along x (issue 37 item 6): its message
# must be in log.lammps, which rank 0 writes (tests/crafted_scenes.py RANK_ONE_GUARDS; the test with
# the screen output discarded: tests/cases/test_guards.py).
RANK_ONE_WHY = {
    "max_speed": "a particle too fast on rank 1: the motion guard stops every rank with rank 1's message",
    "max_wall_overlap": "a particle pushed into a mesh on rank 1: the wall-overlap guard names it in the log",
    "max_crossed": "a centre pushed through a wall on rank 1: the squeeze ledger's crossing guard names it in the log",
    "max_contacts": "a particle on rank 1 with more screw contacts than max_contacts: rank 1 alone stops "
                    "(error->one) and appends its message to the log",
}
CASES += [BadInput(f"guards.rank-1-{name.replace('_', '-')}-np2", words, why=RANK_ONE_WHY[name], lmp_input=text,
                   files=files, nprocs=2)
          for name, (text, files, words) in RANK_ONE_GUARDS.items()]
