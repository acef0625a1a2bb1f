"""Readers for LIGGGHTS particle dumps: `dump custom` text and `dump custom/vtk` legacy VTK.

Both give ParticleFrame objects with the dump's per-particle columns under their `dump custom`
names (id, type, x, y, z, vx, vy, vz, radius, ...); VTK vectors such as `v` are split into vx, vy, vz
so that code downstream does not care which kind of dump it got.
"""
from __future__ import annotations

import re
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .run_files import AnalysisInputError

DUMP_PATTERNS = ("particles_*.txt", "particles_*.vtk")
BOUNDING_BOX = "boundingBox"  # dump custom/vtk also writes particles_boundingBox_<step>.vtk: the box, no particles
_STEP_IN_NAME = re.compile(r"(\d+)(?!.*\d)")
_INTEGER_COLUMNS = ("id", "type")


@dataclass(frozen=True)
class Box:
    lo: np.ndarray  # (3,) m
    hi: np.ndarray  # (3,) m
    periodic: tuple[bool, bool, bool]


@dataclass(frozen=True)
class ParticleFrame:
    step: int
    columns: dict[str, np.ndarray]
    box: Box | None = None  # text dumps carry it, VTK dumps do not

    def __len__(self) -> int:
        return len(self.columns["x"])

    def require(self, *names: str) -> None:
        missing = [n for n in names if n not in self.columns]
        if missing:
            raise AnalysisInputError(f"dump frame at step {self.step} lacks {', '.join(missing)} "
                                     f"(has {', '.join(self.columns)}); add them to the dump command")

    @property
    def volume(self) -> np.ndarray:
        self.require("radius")
        return 4.0 / 3.0 * np.pi * self.columns["radius"] ** 3


def step_from_name(path: Path) -> int:
    """`particles_12000.vtk` -> 12000 (LIGGGHTS replaces '*' in the dump file name by the step)."""
    match = _STEP_IN_NAME.search(Path(path).stem)
    if match is None:
        raise AnalysisInputError(f"{path}: no time step in the file name")
    return int(match.group(1))


def find_dump_files(run_dir: Path | str) -> tuple[list[Path], list[str]]:
    """Dump files of a run in step order, and notes. Text dumps win if both kinds are present
    (they carry the box, which periodic mass-flow counting needs)."""
    dumps = Path(run_dir) / "dumps"
    found = {pattern: sorted((p for p in dumps.glob(pattern) if BOUNDING_BOX not in p.name), key=step_from_name)
             for pattern in DUMP_PATTERNS}
    text, vtk = found[DUMP_PATTERNS[0]], found[DUMP_PATTERNS[1]]
    if text and vtk:
        return text, [f"dumps/ holds text and VTK dumps: using the {len(text)} text dumps"]
    return text or vtk, []


class _IncompleteFrame(Exception):
    """A frame that ends before its last particle: what a killed run leaves at the end of a file."""


def read_text_dump(path: Path | str) -> tuple[list[ParticleFrame], list[str]]:
    """All frames of a `dump custom` file. An incomplete last frame (run killed mid-write) is
    dropped with a note; a damaged frame before it is an error."""
    path = Path(path)
    if not path.is_file():
        raise AnalysisInputError(f"{path}: file not found")
    data = path.read_text(encoding="utf-8", errors="replace")
    issues: list[str] = []
    cut = data.rfind("\n") + 1
    if cut < len(data):
        data = data[:cut]  # a number cut in half would otherwise parse as a wrong number
    chunks = data.split("ITEM: TIMESTEP")
    if chunks[0].strip() or len(chunks) < 2:
        raise AnalysisInputError(f"{path}: not a LIGGGHTS `dump custom` file (no 'ITEM: TIMESTEP' at the start)")
    frames = []
    for number, chunk in enumerate(chunks[1:], start=1):
        is_last = number == len(chunks) - 1
        try:
            frames.append(_parse_text_frame(chunk))
        except _IncompleteFrame as err:
            if not is_last:
                raise AnalysisInputError(f"{path}: frame {number} is incomplete ({err})") from None
            issues.append(f"{path.name}: last frame is incomplete ({err}), dropped")
        except (ValueError, IndexError, KeyError) as err:
            raise AnalysisInputError(f"{path}: frame {number} cannot be read: {err}") from None
    return frames, issues


def _parse_text_frame(chunk: str) -> ParticleFrame:
    head, separator, rows = chunk.partition("ITEM: ATOMS")
    if not separator:
        raise _IncompleteFrame("no ATOMS section")
    lines = head.split("\n")
    step = int(lines[1])
    items = {line.split(":")[1].split()[0]: i for i, line in enumerate(lines) if line.startswith("ITEM:")}
    n_atoms = int(lines[items["NUMBER"] + 1])
    box_line = lines[items["BOX"]].split()
    x_flag, y_flag, z_flag = box_line[-3:]
    bounds = np.array([[float(w) for w in lines[items["BOX"] + k].split()[:2]] for k in (1, 2, 3)])
    box = Box(bounds[:, 0], bounds[:, 1], (x_flag == "pp", y_flag == "pp", z_flag == "pp"))
    names_line, _, body = rows.partition("\n")
    names = names_line.split()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy warns, rather than raises, when it meets a non-number
        try:
            flat = np.fromstring(body, sep=" ") if body.strip() else np.empty(0)
        except DeprecationWarning:
            raise ValueError("non-numeric particle data") from None
    if flat.size < n_atoms * len(names):
        raise _IncompleteFrame(f"{flat.size // max(len(names), 1)} of {n_atoms} particles")
    if flat.size > n_atoms * len(names):
        raise ValueError(f"more values than {n_atoms} particles x {len(names)} columns")
    table = flat.reshape(n_atoms, len(names))
    columns = {name: table[:, i].astype(np.int64) if name in _INTEGER_COLUMNS else table[:, i]
               for i, name in enumerate(names)}
    frame = ParticleFrame(step, columns, box)
    frame.require("x", "y", "z")
    return frame


def read_vtk_dump(path: Path | str) -> ParticleFrame:
    """One `dump custom/vtk` file (legacy VTK polydata); the step comes from the file name."""
    import pyvista as pv  # heavy import, only needed for VTK dumps

    path = Path(path)
    if not path.is_file():
        raise AnalysisInputError(f"{path}: file not found")
    try:
        mesh = pv.read(path)
    except Exception as err:  # VTK reports damaged files with assorted exception types
        raise AnalysisInputError(f"{path}: cannot be read as VTK ({err})") from None
    if mesh.n_points == 0:
        raise AnalysisInputError(f"{path}: no particles (empty or truncated VTK file)")
    points = np.asarray(mesh.points, dtype=np.float64)
    columns: dict[str, np.ndarray] = {"x": points[:, 0], "y": points[:, 1], "z": points[:, 2]}
    for name in mesh.point_data.keys():
        values = np.asarray(mesh.point_data[name])
        if values.ndim == 2 and values.shape[1] == 3:
            for axis, component in enumerate("xyz"):
                columns[f"{name}{component}"] = values[:, axis].astype(np.float64)
        elif values.ndim == 1:
            columns[name] = values.astype(np.int64) if name in _INTEGER_COLUMNS else values.astype(np.float64)
    return ParticleFrame(step_from_name(path), columns)


def read_dump_file(path: Path | str) -> tuple[list[ParticleFrame], list[str]]:
    path = Path(path)
    if path.suffix == ".vtk":
        return [read_vtk_dump(path)], []
    return read_text_dump(path)


def iter_frames(paths: Sequence[Path], issues: list[str] | None = None) -> Iterator[ParticleFrame]:
    """Frames of several dump files in order, one file in memory at a time; notes go to `issues`."""
    for path in paths:
        frames, notes = read_dump_file(path)
        if issues is not None:
            issues.extend(notes)
        yield from frames
