"""The files the case inputs read that are made from the meshes, made for given case values: the
static fill of the periodic case and the feed regions of the full and non-periodic cases.

    python -m tsg_cases.prepared defaults [CASE ...] # the case files' defaults (./tsg setup: periodic, nonperiodic)
    python -m tsg_cases.prepared fill OUT.in --mesh-dir DIR [--d-mean 0.0004] [--psd-sigma 0.05]
        [--rho-p 1263] [--holdup-g 2.7] [--seed 12345]
    python -m tsg_cases.prepared feed OUT.in --mesh-dir DIR [--d-mean 0.0004] [--feed-at element:7]

`defaults` reads the default values of each case file (its `variable ... index` lines, one source)
and makes what they name: the paper-scale meshes (1 um) and build/prepared/periodic-fill.in,
full-feed.in (at element 7, as the seed paper) and nonperiodic-feed.in (at the inlet), so that
`cd cases && lmp -in in.tsg_periodic` runs with no other step. It skips what is up to date.

The fill is a data file read in one `read_data ... add` (FILL.in.data) and its include; the feed
is cases/free_space.py's include. Each include ends with a "made for" block (`variable fill_d_mean
equal ...`, ...). The case inputs compare it with the run's values and, when they differ, stop with
an error that prints the `python -m tsg_cases.prepared` command making the file for the run.
"""
from __future__ import annotations

import argparse
import hashlib
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

from tsg_analysis.run_files import mesh_zones
from tsg_cases import free_space
from tsg_cases.case_parameters import CASE_DIR, defined_variables
from tsg_cases.command_line import run_reporting
from tsg_cases.progress import Heartbeat
from tsg_meshes.build import exclusive_build, tolerance_tag
from tsg_meshes.machine import read_machine

ROOT = CASE_DIR.parent
# The periodic domain's hold-up, g (docs/cases.md, "The periodic hold-up: derived, not given"): at the
# paper's scale, the paper's own particle counts for the domain (Section 3.2: "just under 1200" at
# 1.5 mm, "approximately 4100" at 1.0 mm, "approx. 4.1 M" at 0.1 mm, the same mass at every size:
# 2.68-2.73 g); on the demo machine, the full granulator's mean fill (14.4 kg/h x 3 s = 12 g over
# 500 mm) on the section's 95.83 mm, which its studies and kept states were made with.
PAPER_HOLDUP_G = 2.7
DEMO_HOLDUP_G = 2.3
DEFAULT_SEED = 12345     # the fill seed of cases/run_case.py
FEED_LENGTH = 0.028      # m, axial length of the feed region (cases/run_case.py)
PAPER_FEED = {"periodic": None, "full": "element:7", "nonperiodic": "inlet"}   # seed paper Section 2.3
CONFIG_PREFIX = "consigma1-"


class PrepareError(ValueError):
    """A bad option or a file that cannot be made: one line for the user."""


def feed_range(feed_at: str, mesh_dir: Path) -> tuple[float, float]:
    """Axial extent of the feed region: 'inlet' (2 mm from the inlet wall) or 'element:N' (the start
    of zone N of the meshes' zones.txt), FEED_LENGTH long (as cases/run_case.py)."""
    zones = mesh_zones(mesh_dir)
    if feed_at == "inlet":
        x0 = 0.002
    else:
        number = feed_at[8:] if feed_at.startswith("element:") else ""
        if not (number.isdigit() and 1 <= int(number) <= len(zones)):
            raise PrepareError(f"--feed-at {feed_at} is not allowed: use 'inlet' or 'element:N' with 1 <= N <= {len(zones)}")
        x0 = float(zones.x_start[int(number) - 1])
    return x0, x0 + FEED_LENGTH


def domain_length(mesh_dir: Path) -> float:
    return float(mesh_zones(mesh_dir).x_end[-1])


def fill_files(mesh_dir: Path, d_mean: float, psd_sigma: float, rho_p: float, holdup_g: float, seed: int) -> tuple[str, str]:
    """The fill as (include, data file): `read_data FILL.data add` reads the particles in one command
    (the `create_atoms single` lines of free_space.fill_include cost O(N^2): each one rebuilds the
    atom map; about 5 minutes for the paper's 53 940 particles on 2 loaded cores)."""
    length = domain_length(mesh_dir)
    with Heartbeat(f"placing {holdup_g:g} g of {d_mean * 1e6:g} um particles in {mesh_dir.name}",
                   expected="the paper fill: 250 s of CPU, 30 min on 2 heavily loaded cores"):
        centres, diameters = free_space.fill(mesh_dir, holdup_g * 1e-3, d_mean, psd_sigma, rho_p, (0.0, length), True, seed)
    machine = read_machine(mesh_dir)
    mass_g = rho_p * np.pi / 6 * np.sum(diameters ** 3) * 1e3
    data = [f"LIGGGHTS data file: the periodic fill of cases/prepared.py ({mesh_dir.name}, seed {seed})", "",
            f"{len(diameters)} atoms", "2 atom types", "",
            f"0 {length!r} xlo xhi", f"{-machine['box_y']!r} {machine['box_y']!r} ylo yhi",
            f"{-machine['box_z']!r} {machine['box_z']!r} zlo zhi", "", "Atoms", ""]
    # atom_style granular: ID type diameter density x y z (the density is set to ${rho_p} after reading)
    data += [f"{k} 1 {d:.9e} {rho_p!r} {x:.9e} {y:.9e} {z:.9e}"
             for k, (d, (x, y, z)) in enumerate(zip(diameters, centres), start=1)]
    include = [f"# The periodic fill made by cases/prepared.py from {mesh_dir}: {len(diameters)} particles,",
               f"# {mass_g:.6g} g at rho_p = {rho_p:g} kg/m^3, placed at phase 0; read from ${{fill_file}}.data.",
               "# Run it on an empty box. Requires ${fill_file}, ${rho_p}.",
               "read_data ${fill_file}.data add",
               "set group all density ${rho_p}",
               f"variable fill_count equal {len(diameters)}",
               f"variable d_min equal {diameters.min():.9e}  # smallest diameter, m (time step)"]
    made_for = {"fill_d_mean": d_mean, "fill_psd_sigma": psd_sigma, "fill_rho_p": rho_p, "fill_domain_length": length,
                "fill_holdup_g": holdup_g}
    return "\n".join(include) + "\n" + made_for_block(made_for, "in.tsg_periodic"), "\n".join(data) + "\n"


def fill_count(include: str) -> int:
    """The number of particles a fill include (fill_files) reads."""
    found = re.search(r"^variable fill_count equal (\d+)", include, re.MULTILINE)
    if found is None:
        raise PrepareError("not a fill include of cases/prepared.py: no fill_count line")
    return int(found.group(1))


def feed_text(mesh_dir: Path, d_mean: float, feed_at: str) -> str:
    x0, x1 = feed_range(feed_at, mesh_dir)
    side = 1.6 * 1.5 * d_mean          # cube edge: 1.6 x the largest particle of the PSD (cases/run_case.py)
    corners = free_space.feed_boxes(mesh_dir, (x0, x1), side, 0.1 * d_mean)
    if len(corners) == 0:
        raise PrepareError(f"no free cube of edge {side:g} m between x = {x0:g} and {x1:g} m in {mesh_dir}")
    made_for = {"feed_d_mean": d_mean, "feed_x_start": x0, "feed_x_end": x1, "feed_domain_length": domain_length(mesh_dir)}
    return (merged_feed_include(corners, side, str(mesh_dir)) + made_for_block(made_for, "in.tsg_full and in.tsg_nonperiodic")
            + f"variable feed_at string {feed_at}\n")


def merge_cubes(corners: np.ndarray, side: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """The same space as the cubes of edge `side` at `corners` (n, 3) (a grid), as fewer blocks (lower
    and upper corners): runs of adjacent cubes along x, then runs of equal x-extent along y.
    LIGGGHTS estimates the volume of the feed region by Monte Carlo at every `run` (fix
    insert/rate/region), testing each sample against every block of the union: 7 100 cubes of the
    paper-scale feed kept a run's set-up busy for tens of minutes."""
    if len(corners) == 0:
        return []
    origin = corners.min(axis=0)
    cells = np.rint((corners - origin) / side).astype(int)
    runs: dict[tuple[int, int, int], list[int]] = {}          # (k, i_start, i_end) -> j values
    for (j, k) in sorted({(int(j), int(k)) for _, j, k in cells}):
        column = np.sort(cells[(cells[:, 1] == j) & (cells[:, 2] == k), 0])
        breaks = np.flatnonzero(np.diff(column) > 1)
        for start, end in zip(np.r_[column[0], column[breaks + 1]], np.r_[column[breaks], column[-1]]):
            runs.setdefault((k, int(start), int(end)), []).append(j)
    blocks = []
    for (k, i0, i1), js in runs.items():
        js = sorted(js)
        breaks = np.flatnonzero(np.diff(js) > 1)
        for j0, j1 in zip(np.r_[js[0], np.asarray(js)[breaks + 1]], np.r_[np.asarray(js)[breaks], js[-1]]):
            low = origin + side * np.array([i0, j0, k])
            high = origin + side * np.array([i1 + 1, j1 + 1, k + 1])
            blocks.append((low, high))
    return blocks


def merged_feed_include(corners: np.ndarray, side: float, source: str) -> str:
    blocks = merge_cubes(corners, side)
    lines = [f"# Feed regions made by cases/prepared.py from {source}: {len(corners)} cubes of {side * 1e3:.4g} mm",
             f"# free of the screws and the barrel at phase 0 (so at every half revolution), as {len(blocks)} blocks."]
    names = []
    for n, (low, high) in enumerate(blocks, start=1):
        names.append(f"feed_{n}")
        lines.append(f"region feed_{n} block {low[0]:.9e} {high[0]:.9e} {low[1]:.9e} {high[1]:.9e} "
                     f"{low[2]:.9e} {high[2]:.9e} units box")
    if len(names) == 1:                 # a union needs two regions
        lines.append(f"region feed_{len(names) + 1} block {blocks[0][0][0]:.9e} {blocks[0][1][0]:.9e} {blocks[0][0][1]:.9e} "
                     f"{blocks[0][1][1]:.9e} {blocks[0][0][2]:.9e} {blocks[0][1][2]:.9e} units box")
        names.append(f"feed_{len(names) + 1}")
    lines.append(f"region feed union {len(names)} " + " ".join(names))
    lines.append(f"variable feed_volume equal {len(corners) * side ** 3:.9e}")
    return "\n".join(lines) + "\n"


def made_for_block(values: dict[str, float], checked_by: str) -> str:
    lines = [f"# Made for these values by cases/prepared.py; {checked_by} compare them with the run's."]
    lines += [f"variable {name} equal {value!r}" for name, value in values.items()]
    return "\n".join(lines) + "\n"


def write(path: Path, text: str, key: str, data: str | None = None) -> None:
    """The include (and its data file, PATH.data): never half-written under the names the case reads."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if data is not None:
        partial_data = path.with_name(path.name + ".data.partial")
        partial_data.write_text(data)
        partial_data.replace(path.with_name(path.name + ".data"))
    partial = path.with_name(path.name + ".partial")
    partial.write_text(f"# prepared-key {key}\n" + text)
    partial.replace(path)


def up_to_date(path: Path, key: str, data: bool = False) -> bool:
    if not path.is_file() or (data and not path.with_name(path.name + ".data").is_file()):
        return False
    with open(path) as handle:
        return handle.readline().strip() == f"# prepared-key {key}"


def mesh_key(mesh_dir: Path) -> str:
    """What a made file depends on in the meshes: their zones and machine geometry, and the three
    surfaces (size and modification time: hashing 800 MB of STL would take longer than needed)."""
    digest = hashlib.sha256()
    for name in ("zones.txt", "machine.in"):
        digest.update((mesh_dir / name).read_bytes())
    for name in free_space.MESHES:
        stat = (mesh_dir / name).stat()
        digest.update(f"{name} {stat.st_size} {stat.st_mtime_ns}".encode())
    return digest.hexdigest()[:16]


def default_mesh_dir(case: str, values: dict[str, str]) -> Path:
    """The case file's default mesh_dir, with ${case_dir} = cases/."""
    text = values["mesh_dir"].replace("${case_dir}", str(CASE_DIR))
    return (CASE_DIR / text).resolve()


def build_meshes(mesh_dir: Path) -> None:
    """The meshes the default mesh_dir names: consigma1-<case>-<tolerance>um (tsg_meshes.build), built
    once however many callers start together (tsg_meshes.build.exclusive_build)."""
    def complete() -> bool:
        return (mesh_dir / "zones.txt").is_file() and all((mesh_dir / m).is_file() for m in free_space.MESHES)
    if complete():
        return
    name = mesh_dir.name
    config, _, tag = name.rpartition("-")
    if not (config.startswith(CONFIG_PREFIX) and tag.endswith("um")):
        raise PrepareError(f"mesh_dir {mesh_dir}: not a name tsg_meshes builds (consigma1-<case>-<tolerance>um)")
    tolerance = float(tag[:-2]) * 1e-6
    if tolerance_tag(tolerance) != tag:
        raise PrepareError(f"mesh_dir {mesh_dir}: tolerance tag {tag} does not read back as {tolerance_tag(tolerance)}")
    with exclusive_build(mesh_dir):
        if complete():      # another caller built it while this one waited
            return
        with Heartbeat(f"meshes {name}", expected="the full machine at 1 um: 135 s on 2 heavily loaded cores"):
            proc = subprocess.run([sys.executable, "-m", "tsg_meshes", "build", config, str(mesh_dir), "--tolerance",
                                   str(tolerance)], capture_output=True, text=True)
    if proc.returncode != 0:
        last = proc.stderr.strip().splitlines()[-1:] or ["no message"]
        raise PrepareError(f"building the meshes {mesh_dir} failed: {last[0]}")


def default_target(case: str) -> Path:
    """Where the case file's default fill_file / feed_file points (cases/-relative)."""
    values = defined_variables(case)
    name = "fill_file" if case == "periodic" else "feed_file"
    return (CASE_DIR / values[name].replace("${case_dir}", str(CASE_DIR))).resolve()


def prepare_defaults(cases: tuple[str, ...] = ("periodic", "nonperiodic", "full")) -> list[Path]:
    made = []
    for case in cases:
        values = defined_variables(case)
        mesh_dir = default_mesh_dir(case, values)
        build_meshes(mesh_dir)
        target = default_target(case)
        d_mean = float(values["d_mean"])
        if case == "periodic":
            numbers = (d_mean, float(values["psd_sigma"]), float(values["rho_p"]), PAPER_HOLDUP_G, DEFAULT_SEED)
            key = hashlib.sha256(repr(("fill", numbers, mesh_key(mesh_dir))).encode()).hexdigest()[:16]
            if up_to_date(target, key, data=True):
                print(f"[prepare] {target} is up to date")
                continue
            include, data = fill_files(mesh_dir, *numbers)
            write(target, include, key, data)
        else:
            feed_at = PAPER_FEED[case]
            key = hashlib.sha256(repr(("feed-blocks", d_mean, feed_at, mesh_key(mesh_dir))).encode()).hexdigest()[:16]
            if up_to_date(target, key):
                print(f"[prepare] {target} is up to date")
                continue
            with Heartbeat(f"feed regions of the {case} case ({feed_at}) in {mesh_dir.name}"):
                text = feed_text(mesh_dir, d_mean, str(feed_at))
            write(target, text, key)
        print(f"[prepare] {target} written")
        made.append(target)
    return made


def positive(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text} is not allowed: must be > 0")
    return value


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tsg_cases.prepared", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    d = sub.add_parser("defaults", help="make what the case files' default values name (./tsg setup: periodic, nonperiodic)")
    d.add_argument("cases", nargs="*", choices=["periodic", "nonperiodic", "full"],
                   help="the cases to prepare (default: all three)")
    f = sub.add_parser("fill", help="the periodic case's hold-up, placed in the free space")
    g = sub.add_parser("feed", help="the feed regions of the full and non-periodic cases")
    for p in (f, g):
        p.add_argument("out", type=Path)
        p.add_argument("--mesh-dir", type=Path, required=True)
        p.add_argument("--d-mean", type=positive, default=4e-4, help="mean particle diameter, m")
    f.add_argument("--psd-sigma", type=positive, default=0.05, help="relative standard deviation of the PSD")
    f.add_argument("--rho-p", type=positive, default=1263.0, help="particle density, kg/m^3 (the run's rho_p)")
    f.add_argument("--holdup-g", type=positive, default=PAPER_HOLDUP_G, help="hold-up mass, g")
    f.add_argument("--seed", type=int, default=DEFAULT_SEED)
    g.add_argument("--feed-at", default="element:7", help="'inlet' or 'element:N' (zone N of the meshes)")
    parser.add_argument("--debug", action="store_true", help="show the Python traceback of an error")
    args = parser.parse_args(argv)

    def act() -> int:
        if args.command == "defaults":
            prepare_defaults(tuple(args.cases) or ("periodic", "nonperiodic", "full"))
            return 0
        for name in ("zones.txt", *free_space.MESHES):
            if not (args.mesh_dir / name).is_file():
                raise PrepareError(f"--mesh-dir {args.mesh_dir}: no {name} (build the meshes: python -m tsg_meshes build ...)")
        if args.command == "fill":
            if not 0 <= args.seed < 2**32:
                raise PrepareError(f"--seed {args.seed} is not allowed: 0 <= seed < 2^32")
            text, data = fill_files(args.mesh_dir.resolve(), args.d_mean, args.psd_sigma, args.rho_p, args.holdup_g, args.seed)
            write(args.out, text, "by-hand", data)
        else:
            write(args.out, feed_text(args.mesh_dir.resolve(), args.d_mean, args.feed_at), "by-hand")
        print(f"[prepare] {args.out} written")
        return 0

    return run_reporting("tsg-prepared", act, (PrepareError, RuntimeError, OSError), args.debug)


if __name__ == "__main__":
    sys.exit(main())
