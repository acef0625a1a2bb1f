"""Turn a screw configuration into the files a LIGGGHTS case loads: screw1.stl, screw2.stl,
barrel.stl (ASCII, metres), zones.txt and machine.in (machine geometry, machine.py)."""
from __future__ import annotations

import fcntl
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .barrel import build_barrel
from .machine import MACHINE_FILE, machine_text
from .profile import BORE_RADIUS, CENTRE_DISTANCE, ScrewProfile, TwinBore, profile_for_clearance
from .screw import build_screw, sample_profile
from .spec import ROTATION_SENSE, ScrewConfiguration, read_spec
from .surface import TriangleMesh, edge_neighbour_counts, smallest_angles_deg, write_ascii_stl

CONFIG_DIR = Path(__file__).resolve().parents[1] / "configs"
DEFAULT_TOLERANCE = 5e-6  # metres; see meshes/README.md for why
FINE_TOLERANCE = 1e-6  # paper scale: 1 % of the smallest particle radius, 100 um
MAX_TOLERANCE = 5e-5  # coarser meshes turn the faces between 25-deg-staggered discs into slivers
LIGGGHTS_MIN_ANGLE_DEG = 0.5  # below this `fix mesh/surface` warns about skewed elements
LIGGGHTS_MAX_NEIGHBOURS = 5  # SurfaceMesh<3,5>: edge-sharing neighbours per element
MESH_FILES = ("screw1.stl", "screw2.stl", "barrel.stl")


class MeshQualityError(RuntimeError):
    """A generated mesh that LIGGGHTS would reject or warn about."""


@dataclass
class BuiltGeometry:
    configuration: ScrewConfiguration
    tolerance: float
    screws: tuple[TriangleMesh, TriangleMesh]
    barrel: TriangleMesh
    profile: ScrewProfile = ScrewProfile()
    disc_gap: float = 0.0

    @property
    def length(self) -> float:
        return float(self.configuration.length_mm) / 1000

    def meshes(self) -> dict[str, TriangleMesh]:
        return dict(zip(MESH_FILES, (*self.screws, self.barrel)))


def resolve_config(name_or_path: str) -> Path:
    """A spec file path, or the name of a shipped configuration in meshes/configs/."""
    path = Path(name_or_path)
    if path.is_file():
        return path
    shipped = CONFIG_DIR / f"{name_or_path}.spec"
    if shipped.is_file():
        return shipped
    names = ", ".join(sorted(p.stem for p in CONFIG_DIR.glob("*.spec")))
    raise FileNotFoundError(f"no spec file '{name_or_path}' and no shipped configuration of that name ({names})")


def shipped_configs() -> list[Path]:
    return sorted(CONFIG_DIR.glob("*.spec"))


def generate(configuration: ScrewConfiguration, tolerance: float = DEFAULT_TOLERANCE,
             profile: ScrewProfile = ScrewProfile(), disc_gap: float = 0.0) -> BuiltGeometry:
    if not 0 < tolerance <= MAX_TOLERANCE:
        raise ValueError(f"tolerance {tolerance} m is outside (0, {MAX_TOLERANCE:g}] m")
    polyline = sample_profile(profile, tolerance, configuration.staggers_deg)
    screws = (build_screw(configuration, polyline, 1, tolerance, profile, disc_gap),
              build_screw(configuration, polyline, 2, tolerance, profile, disc_gap))
    barrel = build_barrel(float(configuration.length_mm) / 1000, configuration.ends == "inlet-wall", tolerance)
    geometry = BuiltGeometry(configuration, tolerance, screws, barrel, profile, disc_gap)
    for name, mesh in geometry.meshes().items():
        check_liggghts_constraints(mesh, f"{configuration.name}/{name}")
    return geometry


def check_liggghts_constraints(mesh: TriangleMesh, label: str) -> None:
    smallest = smallest_angles_deg(mesh.corners).min()
    if smallest < LIGGGHTS_MIN_ANGLE_DEG:
        raise MeshQualityError(f"{label}: smallest triangle angle {smallest:.3f} deg < {LIGGGHTS_MIN_ANGLE_DEG} deg")
    neighbours = edge_neighbour_counts(mesh.triangles).max()
    if neighbours > LIGGGHTS_MAX_NEIGHBOURS:
        raise MeshQualityError(f"{label}: a triangle has {neighbours} edge neighbours > {LIGGGHTS_MAX_NEIGHBOURS}")


def write_geometry(geometry: BuiltGeometry, outdir: Path | str) -> list[Path]:
    """Write the meshes, zones.txt and machine.in (machine.in last: its presence with every key marks
    a complete directory). Each file is written beside its target and renamed over it, so a rebuild
    replaces files instead of rewriting them in place (a hard-linked copy keeps its old content)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    written = []
    for name, mesh in geometry.meshes().items():
        write_ascii_stl(mesh, outdir / f"{name}.part", solid_name=Path(name).stem)
        written.append(_finish(outdir / f"{name}.part"))
    (outdir / "zones.txt.part").write_text(zones_text(geometry), encoding="ascii")
    (outdir / f"{MACHINE_FILE}.part").write_text(machine_text(geometry.profile, geometry.disc_gap), encoding="ascii")
    return written + [_finish(outdir / "zones.txt.part"), _finish(outdir / f"{MACHINE_FILE}.part")]


def _finish(part: Path) -> Path:
    target = part.with_suffix("")
    part.replace(target)
    return target


def free_area(profile: ScrewProfile = ScrewProfile(), bore: TwinBore = TwinBore()) -> float:
    """Free section area of the barrel (m^2): the same at every x and every rotation angle."""
    return bore.area_formula() - 2 * profile.area_formula()


def zones_text(geometry: BuiltGeometry) -> str:
    configuration = geometry.configuration
    area = free_area(geometry.profile)
    half = CENTRE_DISTANCE / 2
    lines = [
        f"# tsg_meshes zones: {configuration.name} ({' '.join(configuration.tokens)}), ends {configuration.ends}, "
        f"tolerance {geometry.tolerance:g} m, length {geometry.length:.10e} m",
        f"# axes: screws along +x (flow +x), screw 1 axis at y = {-half:g} m, screw 2 at y = {half:g} m, "
        f"z = 0, z up; screw 2 is screw 1 turned by 90 deg",
        f"# rotation: both screws co-rotate with omega {'>' if ROTATION_SENSE > 0 else '<'} 0 about +x, e.g. "
        f"fix move/mesh ... rotate origin 0 {-half:g} 0 axis 1 0 0 period 0.1 (screw 1; screw 2 at y = {half:g}); "
        f"the opposite sense conveys towards -x",
        f"# free volume = free section area {area:.6e} m^2 (twin bore - 2 screw sections, exact) x zone length",
        "# index type x_start_m x_end_m free_volume_m3",
    ]
    for e in configuration.elements:
        start, end = float(e.x_start_mm) / 1000, float(e.x_end_mm) / 1000
        lines.append(f"{e.index} {e.kind} {start:.10e} {end:.10e} {area * (end - start):.10e}")
    return "\n".join(lines) + "\n"


def tolerance_tag(tolerance: float) -> str:
    return f"{np.format_float_positional(tolerance * 1e6, trim='-')}um"


def mesh_dir_name(configuration_name: str, tolerance: float, barrel_clearance: float | None = None,
                  screw_clearance: float | None = None, disc_gap: float = 0.0) -> str:
    """<name>-<tolerance>um for the paper's machine; + -c<barrel>mm for a clearance-scaled one with
    equal gaps, -c<barrel>-<screw>mm with different gaps (clearances as profile_for_clearance),
    + -g<gap>mm with spacers between staggered discs."""
    name = f"{configuration_name}-{tolerance_tag(tolerance)}"
    if disc_gap:
        return f"{mesh_dir_name(configuration_name, tolerance, barrel_clearance, screw_clearance)}-g{_mm(disc_gap)}mm"
    if barrel_clearance is None and screw_clearance is None:
        return name
    profile = profile_for_clearance(barrel_clearance, screw_clearance)
    gaps = [BORE_RADIUS - profile.outer_radius, CENTRE_DISTANCE - profile.outer_radius - profile.root_radius]
    tags = [_mm(gap) for gap in gaps]
    return f"{name}-c{tags[0]}mm" if tags[0] == tags[1] else f"{name}-c{tags[0]}-{tags[1]}mm"


def _mm(length: float) -> str:
    return np.format_float_positional(round(length * 1e3, 6), trim='-')


def build_all(outdir: Path | str) -> list[Path]:
    """Every shipped configuration at the default tolerance, and the periodic kneading-block
    domain also at the paper-scale tolerance; each into <outdir>/<name>-<tolerance>um/."""
    outdir = Path(outdir)
    builds = [(path, DEFAULT_TOLERANCE) for path in shipped_configs()]
    builds.append((CONFIG_DIR / "consigma1-periodic.spec", FINE_TOLERANCE))
    written = []
    for path, tolerance in builds:
        configuration = read_spec(path)
        geometry = generate(configuration, tolerance)
        written += write_geometry(geometry, outdir / mesh_dir_name(configuration.name, tolerance))
    return written


@contextmanager
def exclusive_build(outdir: Path) -> Iterator[None]:
    """Holds an exclusive lock on `<outdir>.lock` (beside it) while the caller checks whether a mesh
    directory is complete and builds it: runs started together (ctest in parallel, a sweep on a
    cluster) build a shared directory once, and none reads it half-written. An advisory lock
    (flock): only callers that take it are kept out."""
    outdir.parent.mkdir(parents=True, exist_ok=True)
    with open(outdir.with_name(outdir.name + ".lock"), "w") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)
