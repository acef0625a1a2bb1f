"""Bad input to the measurement styles (fix residence/time, compute element/stats, fix massflow/planes)."""
from __future__ import annotations

from badinput import BadInput

BOX = """units si
atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
region box block 0 0.1 -0.01 0.01 -0.01 0.01 units box
create_box 1 box
"""

CASES: list[BadInput] = [
    BadInput("measure.residence.zones-missing",
             ("zones file 'nope.txt'", "missing or not readable"),
             why="the element boundaries of every measurement come from the zones file",
             lmp_input=BOX + "fix rt all residence/time records r.txt zones nope.txt\n"),
]
