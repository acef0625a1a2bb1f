"""Bad input to fix balance/x and to the cases' balance_every (tests/errors/README.md)."""
from __future__ import annotations

from badinput import BadInput
from table_cases import refused

BASE = """atom_style    granular
atom_modify   map array
boundary      f f f
newton        off
communicate   single vel yes
units         si
processors    {grid}
region        box block 0 {length} 0 0.01 0 0.01 units box
create_box    1 box
neighbor      0.0005 bin
fix m1 all property/global youngsModulus peratomtype 5.0e7
fix m2 all property/global poissonsRatio peratomtype 0.25
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
create_atoms 1 single 0.002 0.005 0.005 units box
set atom * diameter 0.001 density 2500
group half id 1
timestep 1e-5
"""


def balance(id: str, command: str, words: tuple[str, ...], why: str, grid: str = "* 1 1", nprocs: int = 2,
            length: float = 0.1) -> BadInput:
    text = BASE.format(grid=grid, length=length) + command + "\nrun 10\n"
    return BadInput(f"balance.{id}", words, why=why, lmp_input=text, nprocs=nprocs)


CASES: list[BadInput] = [
    balance("every-zero", "fix b all balance/x 0", ("fix b balance/x", "interval N in steps", "integer >= 1", "'0'"),
            "a cut move needs a positive interval; 0 would balance never (leave the fix out for that)"),
    balance("every-negative", "fix b all balance/x -100", ("fix b balance/x", "integer >= 1", "'-100'"),
            "a negative interval means nothing"),
    balance("every-fraction", "fix b all balance/x 2.5", ("fix b balance/x", "integer >= 1", "'2.5'"),
            "steps are whole numbers; 2.5 must not be read as 2"),
    balance("every-missing", "fix b all balance/x", ("fix b balance/x", "needs one argument"),
            "the interval has no default"),
    balance("extra-argument", "fix b all balance/x 100 weight contacts", ("fix b balance/x", "needs one argument",
                                                                         "'100 ...'"),
            "only particle counts are balanced; an unknown keyword must not be ignored"),
    balance("group", "fix b half balance/x 100", ("fix b balance/x", "group 'half'", "use group all"),
            "the work of a rank is all its particles, not a group's"),
    balance("grid-y", "fix b all balance/x 100", ("fix b balance/x", "processor grid is 1 x 2 x 1",
                                                  "processors * 1 1"),
            "cuts move along x only: a grid split along y or z cannot be balanced along the screws", grid="1 * 1"),
    balance("grid-2x2", "fix b all balance/x 100", ("processor grid is 2 x 2 x 1", "balance along x needs"),
            "a 2 x 2 grid would be balanced in x only while the y split stays equal", grid="2 2 1", nprocs=4),
    balance("slabs-too-thin", "fix b all balance/x 100", ("fix b balance/x", "4 slabs of at least the neighbour cutoff",
                                                          "box length 0.003 m", "use fewer ranks"),
            "a slab thinner than the neighbour cutoff could be jumped by a particle between two re-neighbourings",
            nprocs=4, length=0.003),
    *refused("full", "balance_every", -1, ("steps between moves of the x cuts", "or 0 for equal slabs"),
             "the cases' load balance interval: >= 1 steps, or 0 for LIGGGHTS' equal slabs"),
]
