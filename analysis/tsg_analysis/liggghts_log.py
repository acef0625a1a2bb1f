"""Read a LIGGGHTS log file: thermo blocks, warnings, errors."""
from __future__ import annotations

import re

import numpy as np

_WARNING = re.compile(r"WARNING: (.*?) \(([\w./-]+\.(?:cpp|h)):(\d+)\)", re.DOTALL)
_ERROR = re.compile(r"ERROR(?: on proc \d+)?: (.*?)(?: \(([\w./-]+\.(?:cpp|h)):(\d+)\))?$", re.MULTILINE)


def parse_warnings(log: str) -> list[str]:
    """Warning texts, whitespace-normalised (LIGGGHTS warnings may span several lines)."""
    return [" ".join(m.group(1).split()) for m in _WARNING.finditer(log)]


def parse_errors(text: str) -> list[str]:
    return [m.group(1).strip() for m in _ERROR.finditer(text)]


def parse_thermo(log: str) -> list[dict[str, np.ndarray]]:
    """One dict (column -> values) per thermo block: a header line starting with 'Step' up to
    'Loop time of'. LIGGGHTS prints variables and computes without their v_/c_ prefix."""
    blocks: list[dict[str, np.ndarray]] = []
    columns: list[str] | None = None
    rows: list[list[float]] = []

    def close() -> None:
        blocks.append({c: np.array([r[i] for r in rows]) for i, c in enumerate(columns or [])})

    for line in log.splitlines():
        words = line.split()
        if columns is None:
            if words and words[0] == "Step" and len(words) > 1:
                columns, rows = words, []
            continue
        if line.startswith("Loop time of"):
            close()
            columns = None
            continue
        if len(words) != len(columns):
            continue  # interleaved messages (warnings, insertion reports)
        try:
            rows.append([float(w) for w in words])
        except ValueError:
            continue
    if columns is not None and rows:  # the run died mid-block: keep what was printed
        close()
    return blocks
