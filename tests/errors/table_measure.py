"""Bad input to the measurement styles (fix residence/time, compute element/stats, fix massflow/planes):
keywords, zones files, planes, restarts that would mix two set-ups, output paths that collide, and an
error raised on rank 1 only. Rows of the bad-input campaign (tests/errors/README.md)."""
from __future__ import annotations

from pathlib import Path

from badinput import BadInput
from measure.measure_cases import (BASE, RESTART_BASE, ZONES, Mover, lanes, particles_include, plane_stl, variables,
                                   zones_text)
from tsg_harness import run_lmp

ZONE_FILES = {
    "good.txt": zones_text(),
    "short.txt": "# header\n1 conveying 0.01 0.03 2e-6\n2 kneading 0.03 0.04\n",
    "type.txt": "1 conveying 0.01 0.03 2e-6\n2 mixing 0.03 0.04 1e-6\n",
    "overlap.txt": "1 conveying 0.01 0.03 2e-6\n2 kneading 0.025 0.04 1e-6\n",
    "unsorted.txt": "1 conveying 0.03 0.04 2e-6\n2 kneading 0.01 0.02 1e-6\n",
    "outside.txt": "1 conveying 0.01 0.03 2e-6\n2 kneading 0.09 0.12 1e-6\n",
    "number.txt": "1 conveying 0.01 0.03mm 2e-6\n",
    "comma.txt": "1 conveying 0,01 0,03 2e-6\n",
    "empty.txt": "# nothing here\n",
}
TWO_MOVERS = particles_include([Mover(0.02, 0.1, 0.0, 0.0), Mover(0.05, 0.1, 0.005, 0.0)])
FILES = {**ZONE_FILES, "particles.include": TWO_MOVERS, "plane.stl": plane_stl(0.03)}


def simple(id: str, command: str, words: tuple[str, ...], why: str, periodic: bool = False,
           after: str = "run 10\n", intact: tuple[str, ...] = (), nprocs: int = 1) -> BadInput:
    """Measurement commands in the deterministic two-particle box of measure_cases."""
    text = BASE + "include particles.include\nfix integr all nve/sphere\n" + command + "\ntimestep 1e-4\n" + after
    return BadInput(f"measure.{id}", words, why=why, lmp_input=text, files=FILES,
                    variables=variables(periodic, px=nprocs), intact=intact, nprocs=nprocs)


RT = "fix rt all residence/time records r.txt zones "
MF = "fix mf all massflow/planes planes 2 0.02 0.06 window 100 "

KEYWORDS = [
    # zones files (the same reader serves the fix and the compute)
    simple("residence.zones-missing", RT + "nope.txt", ("zones file 'nope.txt'", "missing or not readable"),
           "the element boundaries of every measurement come from the zones file"),
    simple("zones.short-line", RT + "short.txt", ("short.txt", "line 3", "expected 5 fields", "found 4"),
           "a zone line needs index, type, x_start, x_end and free volume"),
    simple("zones.bad-type", RT + "type.txt", ("line 2", "type 'mixing'", "conveying, kneading, chopping"),
           "only the three element types of the screw are known"),
    simple("zones.overlap", RT + "overlap.txt", ("line 2", "overlaps zone 1 (line 1)"),
           "a particle must belong to one zone at a time"),
    simple("zones.unsorted", RT + "unsorted.txt", ("line 2", "must be sorted by x_start"),
           "zones are looked up by bisection along x"),
    simple("zones.units", RT + "number.txt", ("line 1", "x_end '0.03mm'", "not a finite number"),
           "positions are plain numbers in metres"),
    simple("zones.decimal-comma", RT + "comma.txt", ("line 1", "x_start '0,01'", "not a finite number"),
           "a decimal comma would be read as 0 by a lax parser"),
    simple("zones.empty", RT + "empty.txt", ("empty.txt", "no zones"), "a zones file without zones measures nothing"),
    simple("zones.outside-box", RT + "outside.txt",
           ("line 2", "zone 2 [0.09, 0.12]", "outside the simulation box along x [0, 0.1]"),
           "a zone outside the box can never hold a particle"),
    # planes and keywords of fix residence/time
    simple("residence.inlet-outside", RT + "good.txt inlet 0.2", ("inlet plane x = 0.2", "outside the simulation box"),
           "a plane outside the box is never crossed"),
    simple("residence.outlet-outside", RT + "good.txt outlet -0.01",
           ("outlet plane x = -0.01", "outside the simulation box"), "a plane outside the box is never crossed"),
    simple("residence.reference-at-hi", RT + "good.txt periodic 0.1",
           ("periodic reference plane x = 0.1", "[0, 0.1)"), "on a periodic axis hi is the same plane as lo",
           periodic=True),
    simple("residence.outlet-before-inlet", RT + "good.txt inlet 0.05 outlet 0.04",
           ("outlet 0.04 must lie downstream (+x) of inlet 0.05",), "flow runs towards +x"),
    simple("residence.periodic-needs-periodic-box", RT + "good.txt periodic 0.0",
           ("'periodic' needs a box periodic in x",), "passes are defined on a periodic axis only"),
    simple("residence.periodic-box-needs-keyword", RT + "good.txt outlet 0.09", ("box is periodic in x", "periodic X"),
           "on a periodic axis a residence is a pass between crossings of a reference plane", periodic=True),
    simple("residence.periodic-and-outlet", RT + "good.txt periodic 0.0 outlet 0.09",
           ("'periodic' cannot be combined with 'inlet' or 'outlet'",), "the two modes exclude each other",
           periodic=True),
    simple("residence.analysis-reversed", RT + "good.txt analysis 0.09 0.01",
           ("analysis XLO XHI = 0.09 0.01", "XLO < XHI"), "an empty analysis domain measures nothing"),
    simple("residence.analysis-outside", RT + "good.txt analysis -0.05 0.09", ("analysis XLO plane x = -0.05",),
           "the analysis domain must lie in the box"),
    simple("residence.not-a-number", RT + "good.txt inlet 5cm", ("inlet value '5cm' is not a finite number",),
           "positions are plain numbers in metres"),
    simple("residence.nan-plane", RT + "good.txt outlet nan", ("outlet value 'nan' is not a finite number",),
           "a NaN plane is never crossed"),
    simple("residence.existing-value", RT + "good.txt existing maybe", ("existing = 'maybe'", "'tag' or 'wait'"),
           "only the two documented policies exist"),
    simple("residence.flush-zero", RT + "good.txt flush 0", ("flush = '0'", "positive integer"),
           "records are written every N > 0 steps"),
    simple("residence.inside-value", RT + "good.txt inside maybe", ("inside = 'maybe'", "'yes' or 'no'"),
           "yes or no only"),
    simple("residence.append-value", RT + "good.txt append 1", ("append = '1'", "'yes' or 'no'"), "yes or no only"),
    simple("residence.unknown-keyword", RT + "good.txt speed 3", ("unknown keyword 'speed'", "allowed: zones, records"),
           "a misspelt keyword must not be ignored"),
    simple("residence.missing-records", "fix rt all residence/time zones good.txt", ("missing 'records FILE'",),
           "records are the measurement"),
    simple("residence.keyword-without-value", RT + "good.txt inlet", ("keyword 'inlet' needs 1 value(s)",),
           "a keyword without its value"),
    simple("residence.renumbered-ids", RT + "good.txt outlet 0.09", ("particle id changed from 2 to 1", "compress no"),
           "records would name the wrong particles after delete_atoms ... compress yes",
           after="run 10\nregion first block 0.01 0.03 -0.01 0.01 -0.01 0.01 units box\n"
                 "delete_atoms region first compress yes\nrun 10\n"),
    # compute element/stats
    simple("element-stats.missing-file", "compute es all element/stats zones nope.txt",
           ("compute es element/stats", "zones file 'nope.txt'"), "the elements come from the zones file"),
    simple("element-stats.outside-box", "compute es all element/stats zones outside.txt\n"
           "thermo_style custom step c_es[1][1]",
           ("compute es element/stats", "zone 2 [0.09, 0.12]", "outside the simulation box"),
           "a zone outside the box can never hold a particle"),
    simple("element-stats.syntax", "compute es all element/stats good.txt",
           ("expected 'compute ID group element/stats zones ZONES_FILE'",), "the keyword 'zones' names the file"),
    # fix massflow/planes
    simple("massflow.sensor-outside", "fix mf all massflow/planes planes 2 0.05 0.15 window 100",
           ("plane 2 at x = 0.15", "outside the simulation box along x [0, 0.1]"), "a sensor outside the box sees nothing"),
    simple("massflow.sensor-at-periodic-hi", "fix mf all massflow/planes planes 1 0.1 window 100",
           ("plane 1 at x = 0.1", "[0, 0.1)"), "on a periodic axis hi is the same plane as lo", periodic=True),
    simple("massflow.sensor-count", "fix mf all massflow/planes planes 3 0.05 0.06 window 100",
           ("plane 3 position 'window' is not a finite number", "'planes 3' needs 3 positions"),
           "the count and the positions must agree"),
    simple("massflow.no-window", "fix mf all massflow/planes planes 1 0.05", ("missing 'window N'",),
           "a rate needs an averaging window"),
    simple("massflow.window-zero", "fix mf all massflow/planes planes 1 0.05 window 0",
           ("window = '0' must be a positive number of steps",), "a rate needs a window of at least one step"),
    simple("massflow.bad-count", "fix mf all massflow/planes planes two 0.05 window 10",
           ("sensor count K between 1 and 1000, got 'two'",), "the count is an integer"),
    simple("massflow.append-value", MF + "file m.txt append maybe", ("append = 'maybe'", "'yes' or 'no'"),
           "yes or no only"),
]

# ---- output paths that collide -------------------------------------------------------------------
PATHS = [
    simple("paths.records-is-zones-file", "fix rt all residence/time zones good.txt records good.txt outlet 0.09",
           ("the records file of fix rt residence/time 'good.txt' is the same file as the zones file",
            "choose another file name"), "writing the records would destroy the zones file", intact=("good.txt",)),
    simple("paths.records-is-zones-file-spelt-differently",
           "shell mkdir sub\nfix rt all residence/time zones good.txt records ./sub/../good.txt outlet 0.09",
           ("'./sub/../good.txt' is the same file as the zones file of fix rt residence/time 'good.txt'",),
           "two spellings of one path are one file", intact=("good.txt",)),
    simple("paths.records-is-massflow-file", RT + "good.txt outlet 0.09\n" + MF + "file r.txt",
           ("the mass-flow file of fix mf massflow/planes 'r.txt' is the same file as the records file of fix rt "
            "residence/time 'r.txt'",), "two fixes writing one file lose a header and interleave their rows"),
    simple("paths.massflow-is-zones-of-compute", "compute es all element/stats zones good.txt\n" + MF + "file good.txt",
           ("the mass-flow file of fix mf massflow/planes 'good.txt' is the same file as the zones file of "
            "compute es element/stats",), "writing the mass flow would destroy the zones file", intact=("good.txt",)),
    simple("paths.zones-is-records-of-a-fix", RT + "good.txt outlet 0.09\ncompute es all element/stats zones r.txt",
           ("the zones file of compute es element/stats 'r.txt' is the same file as the records file of fix rt "
            "residence/time",), "a file that is being written is not a zones file"),
    simple("paths.records-is-log", "fix rt all residence/time zones good.txt records log.lammps outlet 0.09",
           ("the records file of fix rt residence/time 'log.lammps' is the log file of this run",),
           "the records would be mixed into the log"),
    simple("paths.records-is-mesh", "fix wall all mesh/surface file plane.stl type 1\n"
           "fix rt all residence/time zones good.txt records plane.stl outlet 0.09",
           ("the records file of fix rt residence/time 'plane.stl' is the same file as the mesh file",),
           "writing the records would destroy a mesh of the run", intact=("plane.stl", "good.txt")),
    simple("paths.mesh-is-records", RT + "good.txt outlet 0.09\nfix wall all mesh/surface file r.txt type 1",
           ("the mesh file of a mesh fix 'r.txt' is the same file as the records file of fix rt residence/time",),
           "a file that is being written is not a mesh"),
    simple("paths.massflow-missing-folder", MF + "file no/such/folder/m.txt",
           ("cannot open the mass-flow file 'no/such/folder/m.txt' for writing", "No such file or directory"),
           "the folder of an output file must exist"),
]

# ---- restarts: the second part must continue the first, never mix set-ups or overwrite records ----
RECORDS_FIXES = ("fix rt all residence/time zones {zones} records records.txt periodic 0.0 {extra}\n"
                 "fix mf all massflow/planes planes {planes} window 500 file massflow.txt {mf_extra}\n")
FIRST_RUN_STEPS = 3000


def fast_movers() -> str:
    """8 particles at 0.4 ... 0.75 m/s along +x: several complete passes of the 0.1 m periodic box."""
    grid = lanes(8)
    return particles_include([Mover(0.005 + 0.011 * k, 0.4 + 0.05 * k, *grid[k]) for k in range(8)])


def first_part(tmp: Path) -> None:
    """The run that writes records.txt, massflow.txt and state.restart (what the rows must keep)."""
    fixes = RECORDS_FIXES.format(zones="zones.txt", extra="", planes="2 0.0 0.06", mf_extra="")
    text = (BASE + "include particles.include\nfix integr all nve/sphere\n" + fixes +
            f"timestep 1e-4\nthermo 1000\nrun {FIRST_RUN_STEPS}\nwrite_restart state.restart\n")
    run_lmp(text, tmp / "first", variables=variables(True),
            files={"zones.txt": zones_text(), "particles.include": fast_movers()})
    for name in ("records.txt", "massflow.txt", "state.restart"):
        (tmp / name).write_bytes((tmp / "first" / name).read_bytes())
    assert len((tmp / "records.txt").read_text().splitlines()) > 12, "the first part must write records"


def shifted(zones, dx: float, count: int | None = None):
    return [(i, kind, a + dx, b + dx, v) for i, kind, a, b, v in zones[:count]]


def second_part(id: str, words: tuple[str, ...], why: str, zones=ZONES, extra: str = "",
                planes: str = "2 0.0 0.06", mf_extra: str = "", restart: bool = True) -> BadInput:
    fixes = RECORDS_FIXES.format(zones="zones.txt", extra=extra, planes=planes, mf_extra=mf_extra)
    if restart:
        text = RESTART_BASE + "fix integr all nve/sphere\n" + fixes + "timestep 1e-4\nrun 100\n"
    else:
        text = (BASE + "include particles.include\nfix integr all nve/sphere\n" + fixes +
                "timestep 1e-4\nrun 100\n")
    return BadInput(f"measure.{id}", words, why=why, lmp_input=text, prepare=first_part,
                    files={"zones.txt": zones_text(zones), "particles.include": fast_movers()},
                    variables=variables(True), intact=("records.txt", "massflow.txt"))


RESTARTS = [
    second_part("restart.zones-shifted", ("zones file 'zones.txt' does not describe the zones the restart file was "
                                          "written with", "zone 1 x_start: 0.01 in the restart file, 0.015 now",
                                          "content hash"),
                "a zones file of the same count shifted by 5 mm would mix old and new cells",
                zones=shifted(ZONES, 0.005)),
    second_part("restart.zones-fewer", ("4 zones in the restart file, 3 now",),
                "the per-particle zone times would not fit", zones=ZONES[:3]),
    second_part("restart.zones-retyped", ("zone 3 type: chopping in the restart file, kneading now",),
                "a zone of another type would add its time to the wrong type",
                zones=[z if z[0] != 3 else (3, "kneading", *z[2:]) for z in ZONES]),
    second_part("restart.zones-free-volume", ("zone 2 free_volume: 1e-06 in the restart file, 2e-06 now",),
                "the zones come from another mesh", zones=[z if z[0] != 2 else (*z[:4], 2.0e-6) for z in ZONES]),
    second_part("restart.append-no-over-records", ("'append no' would overwrite the records file 'records.txt'",
                                                   "append yes"),
                "continuing from a restart, starting the records anew would lose the first part", extra="append no"),
    second_part("restart.massflow-append-no", ("'append no' would overwrite the mass-flow file 'massflow.txt'",),
                "continuing from a restart, starting the mass flow anew would lose the first part",
                mf_extra="append no"),
    second_part("restart.massflow-planes-moved", ("the restart file was written with planes 2 0 0.06, this fix has "
                                                  "planes 2 0 0.05",),
                "the particles' sides of the old planes do not apply to new ones", planes="2 0.0 0.05"),
    second_part("restart.massflow-planes-fewer", ("written with planes 2 0 0.06, this fix has planes 1 0",),
                "the particles' sides of the old planes do not apply to new ones", planes="1 0.0"),
    second_part("append.records-of-another-setup", ("cannot append to the records file 'records.txt'",
                                                   "# analysis domain: whole axis",
                                                   "# analysis domain: [0.005, 0.095)"),
                "appending to records of another set-up mixes two measurements in one file",
                extra="analysis 0.005 0.095 append yes", restart=False),
    second_part("append.massflow-of-another-setup", ("cannot append to the mass-flow file 'massflow.txt'",
                                                    "# sensor_2 at x = 0.06 m", "# sensor_2 at x = 0.05 m"),
                "appending to a mass-flow record of other sensors mixes two measurements",
                extra="append yes", planes="2 0.0 0.05", mf_extra="append yes", restart=False),
]

# ---- an error raised on rank 1 only reaches log.lammps, after what rank 0 wrote ------------------
MPI = [
    simple("mpi.rank1-error-in-log", RT + "good.txt outlet 0.09\nthermo_style custom step atoms\nthermo 5",
           ("Step Atoms", "Loop time of", "ERROR on proc 1: fix rt residence/time: particle id changed from 2 to 1"),
           "on a cluster stderr is easily lost: the log must hold the error of whichever rank raised it",
           after="run 10\nregion first block 0.0 0.03 -0.01 0.01 -0.01 0.01 units box\n"
                 "delete_atoms region first compress yes\nrun 10\n", nprocs=2),
]

CASES: list[BadInput] = KEYWORDS + PATHS + RESTARTS + MPI
