"""Free space around the screws at phase 0: initial particle fill and feed regions for the cases.

LIGGGHTS does not test inserted particles against meshes, so particles must be placed where the
geometry is not. This module cuts the built STL meshes into axial sections and keeps candidate
spheres that lie inside the barrel, outside both screws and clear of every wall:

  - `fill`: a hold-up mass placed statically in the free space (seed paper Section 2.3.3: the
    periodic case starts from the full model's hold-up "generated statically in the free space
    around the screws"), written as `create_atoms` / `set` commands;
  - `feed`: a union of boxes that are free at phase 0 — and therefore at every half revolution,
    since a two-lobe screw turned by 180° is the same surface — for `fix insert/rate/region`
    inserting once per half revolution (full and non-periodic cases).

    tsg-free-space fill MESH_DIR OUT.in --mass 2.3e-3 --d-mean 1e-3 --sigma 0.05 --density 1263 ...
    tsg-free-space feed MESH_DIR OUT.in --x0 0.005 --x1 0.03 --side 1.5e-3

The fill file sets each particle's density to ${rho_p}, the run's own variable (materials.in or
-var rho_p): --density only sizes the particle count for the target mass and must be that value.
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tsg_cases.command_line import command_parser, run_reporting
from tsg_cases.psd import size_classes
from tsg_meshes.analysis import inside, point_segment_distance, section_segments
from tsg_meshes.surface import read_ascii_stl

MESHES = ("screw1.stl", "screw2.stl", "barrel.stl")


@dataclass
class Sections:
    """Axial sections of the three meshes at the positions xs."""
    xs: np.ndarray
    screws: list[list[np.ndarray]]   # per slice: segments of screw 1, screw 2
    barrel: list[np.ndarray]         # per slice: segments of the bore

    @classmethod
    def cut(cls, mesh_dir: Path, xs: np.ndarray) -> "Sections":
        corners = [read_ascii_stl(mesh_dir / name) for name in MESHES]
        screws, barrel, used = [], [], []
        for x in xs:
            for shift in (0.0, 1e-9, -1e-9, 2e-9):   # a vertex exactly on the plane: nudge it
                try:
                    cut = [section_segments(c, x + shift) for c in corners]
                    break
                except ValueError:
                    continue
            else:
                raise RuntimeError(f"cannot cut the meshes at x = {x}")
            screws.append(cut[:2])
            barrel.append(cut[2])
            used.append(x)
        return cls(np.asarray(used), screws, barrel)

    def clearance(self, index: int, points: np.ndarray, chunk: int = 2000) -> np.ndarray:
        """Signed clearance (m) of points (n, 2) in slice `index`: distance to the nearest wall,
        negative where the point is inside a screw or outside the bore."""
        free = inside(points, self.barrel[index])
        for screw in self.screws[index]:
            free &= ~inside(points, screw)
        walls = np.concatenate([self.barrel[index]] + self.screws[index])
        distance = np.concatenate([point_segment_distance(points[k:k + chunk], walls)
                                   for k in range(0, len(points), chunk)]) if len(points) else np.zeros(0)
        return np.where(free, distance, -distance)


def clear_of_walls(sections: Sections, centres: np.ndarray, radii: np.ndarray, length: float | None,
                   margin: float) -> np.ndarray:
    """Which spheres (centres (n, 3), radii (n,)) keep `margin` from every wall: in every slice
    within ±r of the centre, the sphere's section circle of radius sqrt(r² - h²) must be clear.
    length: period of a periodic axis (slices wrap), or None."""
    ok = np.ones(len(centres), dtype=bool)
    xs = sections.xs
    for index, x in enumerate(xs):
        offset = centres[:, 0] - x
        if length is not None:
            offset = (offset + length / 2) % length - length / 2
        near = np.abs(offset) < radii
        if not near.any():
            continue
        rows = np.flatnonzero(near & ok)
        if rows.size == 0:
            continue
        needed = np.sqrt(radii[rows] ** 2 - offset[rows] ** 2) + margin
        ok[rows] &= sections.clearance(index, centres[rows, 1:]) >= needed
    return ok


class ExactWalls:
    """Exact distance from points to the three meshes (VTK's implicit poly-data distance): the axial
    sections test a sphere only in the slices it spans, and a wall that lies between two slices,
    such as a kneading-disc face, can come closer than the sections show."""

    def __init__(self, mesh_dir: Path, length: float | None):
        import pyvista as pv
        from vtkmodules.vtkFiltersCore import vtkImplicitPolyDataDistance
        self.functions = []
        for name in MESHES:   # one point locator per mesh, built once
            function = vtkImplicitPolyDataDistance()
            function.SetInput(pv.read(mesh_dir / name))
            self.functions.append(function)
        self.length = length

    def distance(self, function, points: np.ndarray) -> np.ndarray:
        from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
        from vtkmodules.vtkCommonCore import vtkDoubleArray
        values = vtkDoubleArray()
        function.FunctionValue(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True), values)
        return np.abs(vtk_to_numpy(values))

    def clear(self, centres: np.ndarray, radii: np.ndarray, margin: float) -> np.ndarray:
        """Which spheres keep `margin` from every mesh (and from its periodic images along x)."""
        ok = np.ones(len(centres), dtype=bool)
        reach = radii + margin
        for function in self.functions:
            ok &= self.distance(function, centres) >= reach
            if self.length is None:
                continue
            for shift in (-self.length, self.length):   # spheres that reach across a periodic end
                images = centres + np.array([shift, 0.0, 0.0])
                near = np.flatnonzero(np.abs(images[:, 0] - np.clip(images[:, 0], 0.0, self.length)) < reach)
                if near.size:
                    ok[near] &= self.distance(function, images[near]) >= reach[near]
        return ok


def bore_box(sections: Sections) -> tuple[np.ndarray, np.ndarray]:
    points = np.concatenate([b.reshape(-1, 2) for b in sections.barrel])
    return points.min(axis=0), points.max(axis=0)


STALLED_BATCHES = 20   # fill: batches in a row that place no particle before the space counts as full


def fill(mesh_dir: Path, mass: float, d_mean: float, sigma: float, density: float, x_range: tuple[float, float],
         periodic: bool, seed: int, margin_fraction: float = 0.05, classes: int = 7):
    """Random sequential placement of spheres (truncated-normal PSD, cases/psd.py) until `mass`.
    Returns centres (n, 3), diameters (n,)."""
    rng = np.random.default_rng(seed)
    relative, fractions = size_classes(sigma, classes)
    diameters_all = d_mean * relative
    particle_mass = density * np.pi / 6 * diameters_all ** 3
    mean_mass = float(np.dot(fractions, particle_mass))
    count = int(np.ceil(mass / mean_mass))
    chosen = np.sort(rng.choice(diameters_all, size=count, p=fractions))[::-1]   # big ones first
    # hit the mass: trim or add to the target (the PSD draw fluctuates)
    while density * np.pi / 6 * np.sum(chosen ** 3) < mass:
        chosen = np.append(chosen, rng.choice(diameters_all, p=fractions))
    chosen = np.sort(chosen)[::-1]
    x0, x1 = x_range
    d_max = diameters_all.max()
    slices = np.arange(x0 + d_max / 16, x1, d_max / 8)   # inside the domain, off the end planes
    sections = Sections.cut(mesh_dir, slices)
    lo, hi = bore_box(sections)
    length = (x1 - x0) if periodic else None
    exact = ExactWalls(mesh_dir, length)
    placed_centres: list[np.ndarray] = []
    placed_d: list[float] = []
    # cell list for the overlap test; on a periodic axis the x cells wrap
    ncell_x = max(1, int((x1 - x0) // d_max))
    cell_x = (x1 - x0) / ncell_x

    def cell(centre: np.ndarray) -> tuple[int, int, int]:
        return (int((centre[0] - x0) // cell_x), int(centre[1] // d_max), int(centre[2] // d_max))

    def neighbours(key: tuple[int, int, int]):
        for dx in (-1, 0, 1):
            kx = key[0] + dx
            if length is not None:
                kx %= ncell_x
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    yield from grid.get((kx, key[1] + dy, key[2] + dz), ())

    def clashes(centre: np.ndarray, d: float) -> bool:
        for j in neighbours(cell(centre)):
            sep = centre - placed_centres[j]
            if length is not None:
                sep[0] = (sep[0] + length / 2) % length - length / 2
            if np.dot(sep, sep) < ((d + placed_d[j]) / 2 * (1 + margin_fraction)) ** 2:
                return True
        return False

    grid: dict[tuple[int, int, int], list[int]] = {}
    remaining = list(chosen)
    # batches until every particle is placed or the space is full: STALLED_BATCHES batches in a row
    # that place nothing (a fixed batch count stopped the paper's 2.7 g at 60 921 of 63 320 particles,
    # at a solid fraction of 0.05, far below where random placement jams)
    empty_batches = 0
    while remaining and empty_batches < STALLED_BATCHES:
        placed_before = len(placed_d)
        d = remaining[0]
        batch = 4000
        inset = 0 if periodic else d / 2
        candidates = np.column_stack([rng.uniform(x0 + inset, x1 - inset, batch),
                                      rng.uniform(lo[0], hi[0], batch), rng.uniform(lo[1], hi[1], batch)])
        good = candidates[clear_of_walls(sections, candidates, np.full(batch, d / 2), length,
                                         margin_fraction * d)]
        good = good[exact.clear(good, np.full(len(good), d / 2), margin_fraction * d)]
        for centre in good:
            if not remaining:
                break
            d = remaining[0]
            if clashes(centre, d):
                continue
            grid.setdefault(cell(centre), []).append(len(placed_centres))
            placed_centres.append(centre)
            placed_d.append(d)
            remaining.pop(0)
        empty_batches = empty_batches + 1 if len(placed_d) == placed_before else 0
    if remaining:
        raise RuntimeError(f"free space too small: placed {len(placed_d)} of {len(chosen)} particles "
                           f"({len(remaining)} left); lower --mass or --d-mean")
    return np.asarray(placed_centres), np.asarray(placed_d)


def feed_boxes(mesh_dir: Path, x_range: tuple[float, float], side: float, margin: float) -> np.ndarray:
    """Lower corners (n, 3) of axis-aligned cubes of edge `side` on a grid over x_range that are
    free of every wall by `margin` at phase 0 (each cube is tested as its circumscribed sphere)."""
    x0, x1 = x_range
    slices = np.arange(x0 + side / 16, x1, side / 8)
    sections = Sections.cut(mesh_dir, slices)
    lo, hi = bore_box(sections)
    grid = np.stack(np.meshgrid(np.arange(x0, x1 - side + 1e-12, side),
                                np.arange(lo[0], hi[0] - side, side),
                                np.arange(lo[1], hi[1] - side, side), indexing="ij"), axis=-1).reshape(-1, 3)
    centres = grid + side / 2
    radius = np.full(len(centres), side * np.sqrt(3) / 2)
    ok = clear_of_walls(sections, centres, radius, None, margin)
    return grid[ok]


def fill_include(centres: np.ndarray, diameters: np.ndarray, density: float, source: str) -> str:
    """create_atoms/set commands; atoms are created grouped by diameter so that `set` takes ranges.
    The density is the run's ${rho_p} (one source); `density` only states the mass in the header."""
    order = np.argsort(-diameters, kind="stable")
    centres, diameters = centres[order], diameters[order]
    lines = [f"# Generated by cases/free_space.py ({source}): {len(diameters)} particles, "
             f"{density * np.pi / 6 * np.sum(diameters ** 3) * 1e3:.6g} g at rho_p = {density:g} kg/m^3, placed at phase 0.",
             "# Atom IDs 1..N in this order; run it on an empty box. Requires ${rho_p}."]
    lines += [f"create_atoms 1 single {x:.9e} {y:.9e} {z:.9e} units box" for x, y, z in centres]
    start = 1
    for diameter in np.unique(diameters)[::-1]:
        count = int(np.sum(diameters == diameter))
        lines.append(f"set atom {start}*{start + count - 1} diameter {diameter:.9e} density ${{rho_p}}")
        start += count
    lines.append(f"variable fill_count equal {len(diameters)}")
    lines.append(f"variable d_min equal {diameters.min():.9e}  # smallest diameter, m (time step)")
    return "\n".join(lines) + "\n"


def feed_include(corners: np.ndarray, side: float, source: str) -> str:
    names = []
    lines = [f"# Generated by cases/free_space.py ({source}): {len(corners)} cubes of {side * 1e3:.4g} mm,",
             "# free of the screws and the barrel at phase 0 and so at every half revolution."]
    for k, (x, y, z) in enumerate(corners, start=1):
        names.append(f"feed_{k}")
        lines.append(f"region feed_{k} block {x:.9e} {x + side:.9e} {y:.9e} {y + side:.9e} "
                     f"{z:.9e} {z + side:.9e} units box")
    lines.append(f"region feed union {len(names)} " + " ".join(names))
    lines.append(f"variable feed_volume equal {len(corners) * side ** 3:.9e}")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser, commands = command_parser("tsg-free-space", __doc__, {
        "fill": "hold-up mass placed in the free space", "feed": "insertion region free at every half revolution"})
    f = commands["fill"]
    f.add_argument("mesh_dir", type=Path)
    f.add_argument("out", type=Path)
    f.add_argument("--mass", type=float, required=True, help="kg")
    f.add_argument("--d-mean", type=float, required=True, help="mean diameter, m")
    f.add_argument("--sigma", type=float, default=0.05, help="relative standard deviation of the PSD")
    f.add_argument("--density", type=float, default=1263.0)
    f.add_argument("--x0", type=float, default=0.0)
    f.add_argument("--x1", type=float, required=True)
    f.add_argument("--periodic", action="store_true")
    f.add_argument("--seed", type=int, default=12345)
    g = commands["feed"]
    g.add_argument("mesh_dir", type=Path)
    g.add_argument("out", type=Path)
    g.add_argument("--x0", type=float, required=True)
    g.add_argument("--x1", type=float, required=True)
    g.add_argument("--side", type=float, required=True, help="cube edge, m")
    g.add_argument("--margin", type=float, default=1e-4, help="clearance from walls, m")
    args = parser.parse_args(argv)
    return run_reporting("tsg-free-space", lambda: run(args), (FreeSpaceError, OSError), args.debug)


class FreeSpaceError(ValueError):
    """A bad option or a fill that cannot be placed: one line for the user."""


def run(args: argparse.Namespace) -> int:
    for name in MESHES:
        if not (args.mesh_dir / name).is_file():
            raise FreeSpaceError(f"{args.mesh_dir / name} does not exist (build the meshes first: ./tsg setup)")
    if args.command == "fill":
        for option, value in (("--mass", args.mass), ("--d-mean", args.d_mean), ("--sigma", args.sigma),
                              ("--density", args.density)):
            if not value > 0:
                raise FreeSpaceError(f"{option} {value} is not allowed: must be > 0")
        if not args.x1 > args.x0:
            raise FreeSpaceError(f"--x1 {args.x1} is not allowed: must be > --x0 {args.x0}")
        try:
            centres, diameters = fill(args.mesh_dir, args.mass, args.d_mean, args.sigma, args.density,
                                      (args.x0, args.x1), args.periodic, args.seed)
        except RuntimeError as problem:
            raise FreeSpaceError(str(problem)) from None
        args.out.write_text(fill_include(centres, diameters, args.density, str(args.mesh_dir)))
        print(f"{len(diameters)} particles written to {args.out}")
    else:
        if not args.side > 0 or not args.x1 > args.x0:
            raise FreeSpaceError(f"--side {args.side}, --x0 {args.x0}, --x1 {args.x1} are not allowed: side > 0, x1 > x0")
        corners = feed_boxes(args.mesh_dir, (args.x0, args.x1), args.side, args.margin)
        if len(corners) == 0:
            raise FreeSpaceError(f"no free cube of edge {args.side} between x = {args.x0} and {args.x1}")
        args.out.write_text(feed_include(corners, args.side, str(args.mesh_dir)))
        print(f"{len(corners)} feed cubes written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
