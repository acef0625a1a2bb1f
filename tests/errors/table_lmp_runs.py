"""Rows of the bad-input campaign (tests/errors/README.md) for faults across `run` commands and for the
command line of lmp: an atom lost between two runs (or two chunks of `run N every M`) while atoms
deleted or inserted on purpose (delete_atoms, fix insert/*, fix outlet/sink) stay allowed
(patches/thermo-cpp.patch, atom-h.patch), fix outlet/sink's own bad input, and `-var NAME` that no line of
the input declares (`check_variables`, patches/variable-*.patch and input-cpp.patch)."""
from __future__ import annotations

import os
from pathlib import Path

from badinput import ROOT, BadInput

# ---- atoms lost between runs ----------------------------------------------------------------------
# Two particles at rest in a closed box (boundary f f f, no gravity): nothing leaves unless moved.
BOX = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box
create_box 1 box
fix m1 all property/global youngsModulus peratomtype 5.0e7
fix m2 all property/global poissonsRatio peratomtype 0.25
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
create_atoms 1 single 0.001 0.001 0.001 units box
create_atoms 1 single -0.001 0.001 0.001 units box
set atom * diameter 0.001 density 2500
fix integr all nve/sphere
timestep 1e-6
thermo_style custom step atoms
thermo_modify lost error
thermo 10
run 20
"""
COUNT = 'print "DONE with $(count(all)) particles"\n'
LOST = ("Lost atoms: 2 at the previous check", "1 now")
GONE = "region gone sphere 0.001 0.001 0.001 0.0005 units box\n"   # holds particle 1 only
INSERT = """fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.0005
fix pdd all particledistribution/discrete 32452843 1 pts 1.0
region feed block -0.008 0.008 -0.008 0.008 -0.008 -0.002 units box
fix feed all insert/pack seed 49979687 distributiontemplate pdd insert_every once overlapcheck yes &
    particles_in_region 5 region feed
"""


def runs(id: str, between: str, words: tuple[str, ...], why: str, accepted: bool = False) -> BadInput:
    return BadInput(f"lmp_runs.{id}", words, why=why, lmp_input=BOX + between + COUNT, accepted=accepted)


LOST_ROWS = [
    runs("lost.between-runs", "set atom 1 z 0.05\nrun 20\n", LOST,
         "an atom moved out of the box between two runs vanished at the next set-up with exit 0 (the count "
         "restarted at every run)"),
    runs("lost.between-chunks", 'run 40 every 10 "set atom 1 z 0.05"\n', LOST,
         "the same between two chunks of run N every M, as the cases run"),
    runs("lost.during-run", "group first id 1\nvelocity first set 0 0 500 units box\nrun 20\n", LOST,
         "the message names the count before and after (upstream printed 'original 1 current 1')"),
    runs("lost.second-run-of-three", "run 20\nset atom 2 x -0.05\nrun 20\n", LOST,
         "the count carries over a run in which nothing happened"),
    runs("allowed.delete-between-runs", GONE + "delete_atoms region gone\nrun 20\n", ("DONE with 1 particles",),
         "delete_atoms updates the count: not a loss", accepted=True),
    runs("allowed.delete-between-chunks", GONE + 'run 40 every 10 "delete_atoms region gone"\n',
         ("DONE with 1 particles",), "the cases' outlet deletes between chunks: not a loss", accepted=True),
    runs("allowed.insert-then-delete", INSERT + "run 20\nunfix feed\n" + GONE + "delete_atoms region gone\nrun 20\n",
         ("DONE with 6 particles",), "fix insert/pack adds 5, delete_atoms removes 1: 2 + 5 - 1", accepted=True),
    runs("allowed.outlet-sink", "fix out all outlet/sink x 0.0\ngroup first id 1\nvelocity first set 1 0 0 units box\n"
         "run 20\n", ("DONE with 1 particles",),
         "fix outlet/sink removes particle 1 past x = 0 during the run: counted as removed, not lost", accepted=True),
    runs("lost.despite-outlet-sink", "fix out all outlet/sink x 0.009\ngroup first id 1\n"
         "velocity first set 0 0 500 units box\nrun 20\n", LOST,
         "a particle leaving sideways before the outlet plane is still a loss"),
    runs("outlet-sink.outside-box", "fix out all outlet/sink x 0.02\nrun 20\n",
         ("fix out outlet/sink", "x 0.02 is not allowed", "inside the box along x (-0.01, 0.01)"),
         "a plane outside the box would never remove anything"),
    runs("outlet-sink.no-plane", "fix out all outlet/sink\nrun 20\n", ("fix out outlet/sink", "needs 'x X'"),
         "the plane has no default"),
    runs("outlet-sink.not-a-number", "fix out all outlet/sink x end\nrun 20\n",
         ("fix out outlet/sink", "needs 'x X'", "got 'x end'"), "a position is a number in m"),
    runs("allowed.ignored-loss", "thermo_modify lost ignore\nset atom 1 z 0.05\nrun 20\nthermo_modify lost error\nrun 20\n",
         ("DONE with 1 particles",),
         "a loss the input chose to ignore is not reported again by the next run", accepted=True),
]

# ---- lmp -var NAME that the input never declares ------------------------------------------------------
BUILD = Path(os.environ.get("TSG_BUILD_DIR", ROOT / "build"))
FILL = """create_atoms 1 single 0.01 0.0 0.0 units box
set atom 1*1 diameter 4e-4 density ${rho_p}
variable fill_count equal 1
variable d_min equal 4e-4
"""
FEED = """region feed_1 block 0.01 0.012 -0.001 0.001 0.008 0.01 units box
region feed_2 block 0.012 0.014 -0.001 0.001 0.008 0.01 units box
region feed union 2 feed_1 feed_2
variable feed_volume equal 1.6e-8
"""
CASE_FILES = {"periodic": ("fill_file", "fill.in", FILL), "nonperiodic": None, "full": ("feed_file", "feed.in", FEED)}


def case_var(case: str, name: str, value: str, words: tuple[str, ...], why: str) -> BadInput:
    """The case input itself with one more -var; a one-particle fill or a one-cube feed stands in for
    the generated include, so the row takes about a second."""
    command = ["{lmp}", "-in", f"{{root}}/cases/in.tsg_{case}", "-echo", "none", "-log", "log.lammps",
               "-var", "case_dir", "{root}/cases", "-var", "mesh_dir", str(BUILD / "meshes" / f"consigma1-{case}-5um"),
               "-var", "out_dir", "{tmp}"]
    files = {}
    if CASE_FILES[case] is not None:
        variable, file_name, content = CASE_FILES[case]
        command += ["-var", variable, file_name]
        files[file_name] = content
    return BadInput(f"lmp_runs.var.{case}.{name}", (f"-var {name} names no variable of the input", *words), why=why,
                    command=command + ["-var", name, value], files=files)


TINY = "variable rpm index 600\nvariable dt_fraction index 0.1\ncheck_variables\nprint \"DONE rpm ${rpm}\"\n"
VAR_ROWS = [
    case_var("periodic", "rmp", "300", ("did you mean rpm",),
             "a misspelt -var was ignored: -var rmp 300 ran at 600 rpm with exit 0"),
    case_var("periodic", "dt_fractoin", "0.05", ("did you mean dt_fraction",),
             "the names declared by the includes (timestep.in) are the list too"),
    case_var("nonperiodic", "feed_rate", "10", ("did you mean feed_rate_kg_h, feed_file",), "a unit suffix left out"),
    case_var("nonperiodic", "colour", "1", ("no declared name is close",), "a name no case knows"),
    case_var("full", "stedy_tolerance", "0.2", ("did you mean steady_tolerance",), "a misspelt -var on the full case"),
    case_var("full", "t_startup", "0.1", ("no declared name is close",),
             "a variable of another case (the full case has no fixed start-up)"),
    BadInput("lmp_runs.var.two-names", ("-var rmp names no variable", "did you mean rpm",
                                        "-var dt_frac names no variable", "did you mean dt_fraction"),
             why="every unclaimed name is listed, not only the first", lmp_input=TINY,
             variables={"rmp": 300, "dt_frac": 0.05}),
    BadInput("lmp_runs.var.declared", ("DONE rpm 300",), why="a declared -var overrides the input's default",
             lmp_input=TINY, variables={"rpm": 300}, accepted=True),
    BadInput("lmp_runs.var.used-not-declared", ("DONE with 42",),
             why="a -var that the input uses (${name}) without a variable line is claimed too",
             lmp_input="print \"used ${width}\"\ncheck_variables\nprint \"DONE with ${width}\"\n",
             variables={"width": 42}, accepted=True),
    BadInput("lmp_runs.var.check-arguments", ("check_variables takes no arguments",),
             why="an argument would suggest a list of names that is not checked", lmp_input="check_variables rpm\n"),
]

CASES: list[BadInput] = LOST_ROWS + VAR_ROWS
