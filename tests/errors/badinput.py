"""Table-driven bad-input campaign (issue: no silent wrong runs).

Every user mistake or fault is one `BadInput` row in a table module (`table_*.py`, one per area).
`check(case, tmp_path)` runs it and asserts, for every row:

- exit status: non-zero (or zero for rows with `accepted=True`: handled, e.g. appended instead of
  overwritten);
- the words of the message: every entry of `words` appears (case-insensitive, whitespace
  normalised) in the message the user sees first: `log.lammps` for lmp runs (the log must hold the
  error of whichever rank raised it), stderr + stdout for command-line tools;
- no Python traceback anywhere in the output;
- no NaN in the log or in any output file the run wrote;
- no lost data: every file named in `intact` has the same bytes after the run as before.

A row runs either an lmp input (`lmp_input`, with `files`, `variables`, `nprocs`) or a command line
(`command`, a list of strings in which "{tmp}", "{root}", "{python}" and "{lmp}" are replaced).
`prepare(tmp)` may create earlier outputs (a restart file, records of a first run) before the row runs.
"""
from __future__ import annotations

import hashlib
import os
import re
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping, Sequence

from tsg_harness import lmp_executable, mpi_command

ROOT = Path(__file__).resolve().parents[2]
TRACEBACK = re.compile(r"Traceback \(most recent call last\)")
NAN = re.compile(r"(?<![A-Za-z_'])[-+]?nan(?![A-Za-z_'])", re.IGNORECASE)  # a quoted 'nan' is the user's text


@dataclass(frozen=True)
class BadInput:
    id: str                                    # unique, "<area>.<what>"
    words: tuple[str, ...]                     # all must appear in the message
    why: str = ""                              # one line for docs/bad-input.md: why it is refused
    lmp_input: str | None = None               # an lmp input text ...
    command: Sequence[str] | None = None       # ... or a command line
    files: Mapping[str, str | bytes | Path] = field(default_factory=dict)
    variables: Mapping[str, object] = field(default_factory=dict)
    nprocs: int = 1
    prepare: Callable[[Path], None] | None = None
    intact: tuple[str, ...] = ()               # files (relative to tmp) that must be unchanged
    accepted: bool = False                     # True: the fault is handled and the run exits 0
    timeout: float = 300
    env: Mapping[str, str] = field(default_factory=dict)


def _normalise(text: str) -> str:
    return " ".join(text.split()).lower()


def _digest(path: Path) -> str | None:
    return hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else None


def _expand(word: str, tmp: Path) -> str:
    return (word.replace("{tmp}", str(tmp)).replace("{root}", str(ROOT))
            .replace("{python}", sys.executable).replace("{lmp}", lmp_executable()))


def run_case(case: BadInput, tmp: Path) -> tuple[int, str, str]:
    """Run one row; returns (exit status, message text the user sees first, all output)."""
    tmp.mkdir(parents=True, exist_ok=True)
    for name, content in case.files.items():
        target = tmp / name
        target.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, Path):
            target.write_bytes(content.read_bytes())
        elif isinstance(content, bytes):
            target.write_bytes(content)
        else:
            target.write_text(content)
    if case.prepare is not None:
        case.prepare(tmp)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", **case.env)
    if case.lmp_input is not None:
        (tmp / "in.case").write_text(case.lmp_input)
        cmd = [lmp_executable(), "-in", "in.case", "-log", "log.lammps", "-echo", "none"]
        for key, value in case.variables.items():
            cmd += ["-var", str(key), str(value)]
        if case.nprocs > 1:
            cmd = mpi_command(case.nprocs) + cmd
    else:
        assert case.command is not None, f"{case.id}: neither lmp_input nor command"
        cmd = [_expand(word, tmp) for word in case.command]
    proc = subprocess.run(cmd, cwd=tmp, capture_output=True, timeout=case.timeout, env=env,
                          encoding="utf-8", errors="replace")
    output = proc.stdout + "\n" + proc.stderr
    if case.lmp_input is not None:
        log = tmp / "log.lammps"
        message = log.read_text(errors="replace") if log.is_file() else ""
    else:
        message = output
    return proc.returncode, message, output


def check(case: BadInput, tmp: Path) -> None:
    before: dict[str, str | None] = {}
    if case.intact:
        # intact files are created by `files` or `prepare`: hash them right before the run
        original_prepare = case.prepare

        def prepare_and_hash(path: Path) -> None:
            if original_prepare is not None:
                original_prepare(path)
            for name in case.intact:
                before[name] = _digest(path / name)
        case = BadInput(**{**case.__dict__, "prepare": prepare_and_hash})
    status, message, output = run_case(case, tmp)
    where = f"[{case.id}] in {tmp}"
    if case.accepted:
        assert status == 0, f"{where}: expected to be handled (exit 0), got exit {status}:\n{output[-3000:]}"
    else:
        assert status != 0, f"{where}: accepted silently (exit 0); it must be refused:\n{output[-3000:]}"
    text = _normalise(message)
    missing = [w for w in case.words if _normalise(_expand(w, tmp)) not in text]
    assert not missing, f"{where}: message lacks {missing}; the user saw:\n{message[-3000:]}"
    assert not TRACEBACK.search(output), f"{where}: a traceback reached the user:\n{output[-3000:]}"
    for path in [tmp / "log.lammps", *sorted(tmp.rglob("*.txt"))]:
        if path.is_file():
            found = NAN.search(path.read_text(errors="replace"))
            assert not found, f"{where}: NaN in {path.name}: ...{found.string[max(0, found.start() - 200):found.end()]}"
    for name, digest in before.items():
        assert digest is not None, f"{where}: intact file {name} did not exist before the run"
        assert _digest(tmp / name) == digest, f"{where}: {name} was changed or removed: data lost"


def ids(cases: Sequence[BadInput]) -> list[str]:
    seen = [c.id for c in cases]
    duplicates = {i for i in seen if seen.count(i) > 1}
    assert not duplicates, f"duplicate case ids: {sorted(duplicates)}"
    return seen

