"""Readers for the measurement files our LIGGGHTS cases write into a run directory.

Formats (fixed by the team, see docs/measurement.md): zones.txt, residence.txt, elements.txt
(stock `fix ave/time ... mode vector`), massflow.txt, squeezes.txt (fix squeeze/ledger). Every reader raises AnalysisInputError with
the file and line for input it cannot use. A last line without its newline is the normal state of
a file whose writer was killed or is still running: it is dropped and said so in `issues`.
"""
from __future__ import annotations

import io
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ELEMENT_TYPES = ("conveying", "kneading", "chopping")
TYPE_LABELS = {"conveying": "C", "kneading": "K", "chopping": "CH"}
EXIT_REASONS = ("outlet", "pass", "deleted", "lost", "inside")
RTD_EXIT_REASONS = ("outlet", "pass")  # a particle that left through the outlet or made one periodic pass
RESIDENCE_MAGIC = "# tsg-dem residence records v1"
RESIDENCE_FIXED_COLUMNS = ("id", "entry_time", "exit_time", "residence_time", "exit_reason",
                           "time_conveying", "time_kneading", "time_chopping")
MASSFLOW_MAGIC = "# tsg-dem mass flow v1"
SQUEEZE_MAGIC = "# tsg-dem squeeze records v1"
SQUEEZE_COLUMNS = ("start_time", "end_time", "id", "x", "y", "z", "radius", "peak_wall_ratio", "peak_pair_ratio",
                   "walls", "kind", "with_particles", "start_speed", "release_speed", "event_number")
SQUEEZE_KINDS = ("two_walls", "wall_and_particles", "wall_alone", "particles")
ELEMENT_COLUMNS = ("solid_fraction", "mean_speed", "mean_axial_velocity", "count", "mass")


class AnalysisInputError(ValueError):
    """An input file that is missing or cannot be used; the message names the file (and line)."""


@dataclass(frozen=True)
class Zones:
    """The screw elements of a run, upstream to downstream (zones.txt)."""

    kind: tuple[str, ...]
    x_start: np.ndarray  # m
    x_end: np.ndarray  # m
    free_volume: np.ndarray  # m^3

    def __len__(self) -> int:
        return len(self.kind)

    @property
    def labels(self) -> list[str]:
        """C1, C2, K1 ... K6, CH1: type letter and running number within the type."""
        seen = dict.fromkeys(ELEMENT_TYPES, 0)
        labels = []
        for kind in self.kind:
            seen[kind] += 1
            labels.append(f"{TYPE_LABELS[kind]}{seen[kind]}")
        return labels

    def ranges(self, kind: str) -> list[tuple[float, float]]:
        """Axial ranges (m) of every zone of one type."""
        return [(float(a), float(b)) for k, a, b in zip(self.kind, self.x_start, self.x_end) if k == kind]

    @property
    def types_present(self) -> list[str]:
        return [t for t in ELEMENT_TYPES if t in self.kind]

    def aligned_labels(self, reference: Zones) -> list[str | None]:
        """Each zone's label in the reference's numbering, zones aligned on their first kneading element
        (a periodic sub-domain against the same elements of the full granulator); None where a zone has
        no counterpart of the same type in the reference."""
        anchor = self.kind.index("kneading") if "kneading" in self.kind else 0
        reference_anchor = reference.kind.index("kneading") if "kneading" in reference.kind else 0
        labels: list[str | None] = []
        for k, kind in enumerate(self.kind):
            j = k - anchor + reference_anchor
            labels.append(reference.labels[j] if 0 <= j < len(reference) and reference.kind[j] == kind else None)
        return labels


@dataclass(frozen=True)
class ResidenceRecords:
    """One record per particle that entered the measured domain (residence.txt)."""

    ids: np.ndarray
    entry_time: np.ndarray
    exit_time: np.ndarray
    residence_time: np.ndarray
    exit_reason: np.ndarray  # strings from EXIT_REASONS
    time_by_type: dict[str, np.ndarray]  # conveying / kneading / chopping -> s per record
    time_by_zone: np.ndarray  # (records, zones) s
    issues: tuple[str, ...] = ()
    # [lo, hi) in m where the times count (the header's "# analysis domain:" line); None: the whole axis
    analysis_domain: tuple[float, float] | None = None

    def __len__(self) -> int:
        return len(self.ids)

    def reason_counts(self) -> dict[str, int]:
        return {reason: int(np.count_nonzero(self.exit_reason == reason)) for reason in EXIT_REASONS}


@dataclass(frozen=True)
class SqueezeRecords:
    """One record per squeeze event (squeezes.txt, fix squeeze/ledger), sorted by end time."""

    columns: dict[str, np.ndarray]  # SQUEEZE_COLUMNS -> values
    wall_names: tuple[str, ...]  # bit k of `walls`
    issues: tuple[str, ...] = ()

    def __len__(self) -> int:
        return len(self.columns["end_time"])

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]


@dataclass(frozen=True)
class ElementStatistics:
    """Time-averaged per-zone statistics, one block per output step (elements.txt)."""

    timesteps: np.ndarray  # (blocks,)
    values: np.ndarray  # (blocks, zones, len(ELEMENT_COLUMNS))
    issues: tuple[str, ...] = ()

    def column(self, name: str) -> np.ndarray:
        """(blocks, zones) array of one of ELEMENT_COLUMNS."""
        return self.values[:, :, ELEMENT_COLUMNS.index(name)]


@dataclass(frozen=True)
class MassFlowRecord:
    """Signed mass flow (kg/h) at the sensors, upstream to downstream (massflow.txt)."""

    step: np.ndarray
    time: np.ndarray  # s
    flow: np.ndarray  # (rows, sensors) kg/h
    sensor_names: tuple[str, ...]
    issues: tuple[str, ...] = ()


def _read_complete_lines(path: Path) -> tuple[str, list[str]]:
    """File text up to its last newline, and an issue if a partial last line was cut off."""
    path = Path(path)
    if not path.is_file():
        raise AnalysisInputError(f"{path}: file not found")
    data = path.read_bytes()
    issues = []
    cut = data.rfind(b"\n") + 1
    if cut < len(data):
        tail = data[cut:].decode(errors="replace").strip()
        if tail:
            issues.append(f"{path.name}: last line is incomplete ({tail[:40]!r}...), dropped "
                          "(was the run killed or still writing?)")
        data = data[:cut]
    try:
        return data.decode("ascii"), issues
    except UnicodeDecodeError as err:
        raise AnalysisInputError(f"{path}: not a text file ({err})") from None


def _header(text: str) -> list[str]:
    """The leading comment lines."""
    header = []
    for line in text.splitlines():
        if not line.startswith("#"):
            break
        header.append(line.strip())
    return header


def _columns_line(path: Path, header: list[str]) -> list[str]:
    for line in header:
        if line.startswith("# columns:"):
            return line.split(":", 1)[1].split()
    raise AnalysisInputError(f"{path}: no '# columns:' header line")


def _first_bad_line(path: Path, text: str, expected_fields: int) -> str:
    """Locate the line that broke a vectorised parse (error path only)."""
    for number, line in enumerate(text.splitlines(), start=1):
        words = line.split()
        if not words or line.lstrip().startswith("#"):
            continue
        if len(words) != expected_fields:
            return f"{path}: line {number} has {len(words)} fields, expected {expected_fields}: {line.strip()[:80]!r}"
        try:
            [float(w) for w in words]
        except ValueError:
            return f"{path}: line {number} is not numeric: {line.strip()[:80]!r}"
    return f"{path}: cannot parse the records"


def _load_table(path: Path, text: str, expected_fields: int) -> np.ndarray:
    """All non-comment lines as a (rows, expected_fields) float array."""
    try:
        with warnings.catch_warnings():   # a file with a header only is a valid, empty table
            warnings.filterwarnings("ignore", message="loadtxt: input contained no data")
            table = np.loadtxt(io.StringIO(text), comments="#", ndmin=2, dtype=np.float64)
    except ValueError:
        raise AnalysisInputError(_first_bad_line(path, text, expected_fields)) from None
    if table.size == 0:
        return np.empty((0, expected_fields))
    if table.shape[1] != expected_fields:
        raise AnalysisInputError(f"{path}: records have {table.shape[1]} fields, the header announces "
                                 f"{expected_fields}")
    return table


def read_zones(path: Path | str) -> Zones:
    path = Path(path)
    text, _ = _read_complete_lines(path)
    kinds, numbers = [], []
    for number, line in enumerate(text.splitlines(), start=1):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        if len(words) != 5 or words[1] not in ELEMENT_TYPES:
            raise AnalysisInputError(f"{path}: line {number}: expected 'index type x_start x_end free_volume' "
                                     f"with type in {ELEMENT_TYPES}, got {line.strip()!r}")
        try:
            numbers.append([float(w) for w in (words[0], *words[2:])])
        except ValueError:
            raise AnalysisInputError(f"{path}: line {number} is not numeric: {line.strip()!r}") from None
        kinds.append(words[1])
    if not kinds:
        raise AnalysisInputError(f"{path}: no zones")
    table = np.array(numbers)
    if not np.array_equal(table[:, 0], np.arange(1, len(kinds) + 1)):
        raise AnalysisInputError(f"{path}: zone indices must run 1..{len(kinds)} in order")
    if np.any(table[:, 2] <= table[:, 1]) or np.any(table[:, 3] <= 0):
        raise AnalysisInputError(f"{path}: every zone needs x_end > x_start and a positive free volume")
    return Zones(tuple(kinds), table[:, 1], table[:, 2], table[:, 3])


def mesh_zones(mesh_dir: Path | str) -> Zones:
    """The element zones of a mesh directory (tsg_meshes writes zones.txt beside the meshes): the
    door to a mesh directory, as `Run` is to a run directory. A zones file itself is accepted too."""
    path = Path(mesh_dir)
    return read_zones(path / "zones.txt" if path.is_dir() else path)


def _records(path: Path, magic: str) -> tuple[str, list[str], list[str], list[str]]:
    """A records file's complete lines, read issues, header lines and column names; refused without
    its magic header line."""
    text, issues = _read_complete_lines(path)
    header = _header(text)
    if magic not in header:
        raise AnalysisInputError(f"{path}: missing the '{magic}' header line")
    return text, issues, header, _columns_line(path, header)


def _analysis_bounds(path: Path, text: str) -> tuple[float, float] | None:
    """'[lo, hi)' -> (lo, hi); 'whole axis' -> None."""
    if text == "whole axis":
        return None
    try:
        lo, hi = (float(v) for v in text.strip("[)").split(","))
    except ValueError:
        raise AnalysisInputError(f"{path}: analysis domain '{text}' is not '[lo, hi)' or 'whole axis'") from None
    return lo, hi


def read_residence(path: Path | str) -> ResidenceRecords:
    path = Path(path)
    text, issues, header, columns = _records(path, RESIDENCE_MAGIC)
    zone_columns = columns[len(RESIDENCE_FIXED_COLUMNS):]
    expected_zones = [f"time_zone_{i}" for i in range(1, len(zone_columns) + 1)]
    if tuple(columns[:len(RESIDENCE_FIXED_COLUMNS)]) != RESIDENCE_FIXED_COLUMNS or zone_columns != expected_zones:
        raise AnalysisInputError(f"{path}: columns must be {' '.join(RESIDENCE_FIXED_COLUMNS)} time_zone_1 ... "
                                 f"time_zone_N, got {' '.join(columns)}")
    # exit_reason is the only word column: turn it into its code so the table parses as floats in C.
    # A plain replace is safe (no number contains these letters) and far faster than a regex.
    for code, reason in enumerate(EXIT_REASONS):
        text = text.replace(reason, str(code))
    table = _load_table(path, text, len(columns))
    codes = table[:, 4]
    if np.any((codes != np.round(codes)) | (codes < 0) | (codes >= len(EXIT_REASONS))):
        raise AnalysisInputError(f"{path}: exit_reason must be one of {', '.join(EXIT_REASONS)}")
    domain = next((line.split(":", 1)[1].strip() for line in header if line.startswith("# analysis domain:")), "whole axis")
    bounds = _analysis_bounds(path, domain)
    return ResidenceRecords(
        analysis_domain=bounds,
        ids=table[:, 0].astype(np.int64),
        entry_time=table[:, 1],
        exit_time=table[:, 2],
        residence_time=table[:, 3],
        exit_reason=np.array(EXIT_REASONS)[codes.astype(np.int64)],
        time_by_type={kind: table[:, 5 + i] for i, kind in enumerate(ELEMENT_TYPES)},
        time_by_zone=table[:, len(RESIDENCE_FIXED_COLUMNS):],
        issues=tuple(issues),
    )


def read_squeezes(path: Path | str) -> SqueezeRecords:
    path = Path(path)
    text, issues, header, columns = _records(path, SQUEEZE_MAGIC)
    if tuple(columns) != SQUEEZE_COLUMNS:
        raise AnalysisInputError(f"{path}: columns must be {' '.join(SQUEEZE_COLUMNS)}, got {' '.join(columns)}")
    table = _load_table(path, text, len(columns))
    kinds = table[:, SQUEEZE_COLUMNS.index("kind")]
    if np.any((kinds != np.round(kinds)) | (kinds < 0) | (kinds >= len(SQUEEZE_KINDS))):
        raise AnalysisInputError(f"{path}: kind must be 0 .. {len(SQUEEZE_KINDS) - 1} ({', '.join(SQUEEZE_KINDS)})")
    walls_line = next((line for line in header if line.startswith("# walls (bit k of the mask):")), "")
    names = tuple(word.split("=", 1)[1] for word in walls_line.split(":", 1)[-1].split() if "=" in word)
    return SqueezeRecords({name: table[:, k] for k, name in enumerate(SQUEEZE_COLUMNS)}, names, tuple(issues))


def earlier_segment_files(run_dir: Path | str, name: str, suffix: str) -> list[Path]:
    """The files NAME.upto-<step>SUFFIX in which cases/slurm/segment.sh keeps each earlier segment's
    output (LIGGGHTS would overwrite it), in step order."""
    prefix = f"{name}.upto-"
    return sorted(Path(run_dir).glob(f"{prefix}*{suffix}"), key=lambda p: int(p.name[len(prefix):-len(suffix)]))


def log_segment_files(run_dir: Path | str) -> list[Path]:
    """A run's LIGGGHTS logs in segment order: the earlier segments' log.upto-<step>.lammps, then
    log.lammps if it exists."""
    current = Path(run_dir) / "log.lammps"
    return earlier_segment_files(run_dir, "log", ".lammps") + ([current] if current.is_file() else [])


def element_segment_files(run_dir: Path | str) -> list[Path]:
    """A run's element statistics files in segment order: the earlier segments' elements.upto-<step>.txt,
    then elements.txt if it exists."""
    current = Path(run_dir) / "elements.txt"
    return earlier_segment_files(run_dir, "elements", ".txt") + ([current] if current.is_file() else [])


def merged_element_text(paths: list[Path]) -> tuple[str, list[str]]:
    """The element statistics of a run's segments as one text, each sampled step once: a continued
    segment starts from a restart file older than the step its predecessor reached, so the later
    segment's blocks win (as in the mass-flow and residence records, whose fixes drop what was written
    after the restart file): each file keeps its blocks before the first step of the next file that
    has blocks; the last keeps all. The first file's header. Reads only (a running segment's file is
    never replaced); also the issues of each file (a cut last line)."""
    if not paths:
        raise AnalysisInputError("no element statistics files (elements.txt or elements.upto-*.txt)")
    parts: list[tuple[list[str], list[tuple[int, list[str]]]]] = []   # (header, blocks) of each file
    issues: list[str] = []
    for path in paths:
        text, cut = _read_complete_lines(path)
        issues += cut
        header: list[str] = []
        blocks: list[tuple[int, list[str]]] = []
        for number, line in enumerate(text.splitlines(), start=1):
            words = line.split()
            if line.startswith("#") and not blocks:
                header.append(line)
            elif len(words) == 2 and all(_is_number(w) for w in words):
                blocks.append((int(float(words[0])), [line]))
            elif words and blocks:
                blocks[-1][1].append(line)
            elif words:
                raise AnalysisInputError(f"{path}: line {number}: expected a block header '<timestep> <rows>', "
                                         f"got {line.strip()!r}")
        parts.append((header, blocks))
    firsts = [blocks[0][0] if blocks else None for _, blocks in parts]
    kept: list[str] = list(parts[0][0])
    for k, (_, blocks) in enumerate(parts):
        limit = next((f for f in firsts[k + 1:] if f is not None), None)
        kept += [line for step, lines in blocks if limit is None or step < limit for line in lines]
    return "\n".join(kept) + "\n", issues


def read_element_statistics(path: Path | str) -> ElementStatistics:
    """elements.txt, or, for a run directory, its segments merged (merged_element_text)."""
    path = Path(path)
    segments = element_segment_files(path) if path.is_dir() else []
    if any(segment.name != "elements.txt" for segment in segments):   # made in segments
        text, issues = merged_element_text(segments)
        path = path / "elements.upto-*.txt and elements.txt"   # the name in messages
    else:
        path = path / "elements.txt" if path.is_dir() else path
        text, issues = _read_complete_lines(path)
    header = _header(text)
    if len(header) < 3 or not header[2].startswith("# Row"):
        raise AnalysisInputError(f"{path}: expected the three '# ...' header lines of fix ave/time mode vector")
    n_values = len(header[2].split()) - 2
    if n_values != len(ELEMENT_COLUMNS):
        raise AnalysisInputError(f"{path}: {n_values} value columns, expected {len(ELEMENT_COLUMNS)} "
                                 f"({' '.join(ELEMENT_COLUMNS)})")
    body = "\n".join(line for line in text.splitlines() if not line.startswith("#"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy only warns when it stops at a non-number
        try:
            flat = np.fromstring(body, sep=" ")
        except (DeprecationWarning, ValueError):
            raise AnalysisInputError(_first_bad_block_line(path, text, n_values)) from None
    if flat.size < 2:
        raise AnalysisInputError(f"{path}: no data blocks")
    n_rows = int(flat[1])
    block = 2 + n_rows * (1 + n_values)  # '<step> <nrows>' then nrows lines '<row> <values>'
    n_blocks = flat.size // block
    if flat.size % block:
        if n_blocks == 0:
            raise AnalysisInputError(f"{path}: the first block is incomplete")
        issues.append(f"{path.name}: last block is incomplete, dropped")
    blocks = flat[:n_blocks * block].reshape(n_blocks, block)
    rows = blocks[:, 2:].reshape(n_blocks, n_rows, 1 + n_values)
    if np.any(blocks[:, 1] != n_rows) or np.any(rows[:, :, 0] != np.arange(1, n_rows + 1)):
        raise AnalysisInputError(_first_bad_block_line(path, text, n_values))
    return ElementStatistics(blocks[:, 0].astype(np.int64), rows[:, :, 1:], tuple(issues))


def _first_bad_block_line(path: Path, text: str, n_values: int) -> str:
    """Walk the blocks line by line to name the first malformed line (error path only)."""
    lines = [(n, line.split()) for n, line in enumerate(text.splitlines(), start=1)
             if line.strip() and not line.startswith("#")]
    i = 0
    while i < len(lines):
        number, words = lines[i]
        if len(words) != 2 or not all(_is_number(w) for w in words):
            return f"{path}: line {number}: expected a block header '<timestep> <rows>', got {' '.join(words)!r}"
        for row in range(1, int(float(words[1])) + 1):
            i += 1
            if i >= len(lines):
                return f"{path}: block at line {number} is incomplete"
            number_r, words_r = lines[i]
            if len(words_r) != 1 + n_values or not all(_is_number(w) for w in words_r) or float(words_r[0]) != row:
                return f"{path}: line {number_r}: expected row {row} with {n_values} values, got {' '.join(words_r)!r}"
        i += 1
    return f"{path}: blocks have differing row counts"


def _is_number(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


def read_massflow(path: Path | str) -> MassFlowRecord:
    path = Path(path)
    text, issues, header, columns = _records(path, MASSFLOW_MAGIC)
    sensors = columns[2:]
    if columns[:2] != ["step", "time"] or not sensors or sensors != [f"sensor_{i}" for i in range(1, len(sensors) + 1)]:
        raise AnalysisInputError(f"{path}: columns must be 'step time sensor_1 ... sensor_K', got {' '.join(columns)}")
    table = _load_table(path, text, len(columns))
    if len(table) and np.any(np.diff(table[:, 1]) <= 0):
        raise AnalysisInputError(f"{path}: time must increase from row to row")
    return MassFlowRecord(table[:, 0].astype(np.int64), table[:, 1], table[:, 2:], tuple(sensors), tuple(issues))
