"""Every case include's "Requires" list is exactly the variables it reads but does not define, so
that the header of an include can be trusted when a case is written or changed."""
from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from tsg_meshes.machine import MACHINE_FILE, machine_values

SOURCE = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
INCLUDES = sorted((SOURCE / "cases" / "include").glob("*.in"))


def header(text: str) -> str:
    lines = []
    for line in text.splitlines():
        if not line.startswith("#"):
            break
        lines.append(line)
    return "\n".join(lines)


def required(text: str) -> set[str] | None:
    """The ${names} from "Requires" to the end of the header comment; None without a Requires."""
    head = header(text)
    at = head.find("Requires")
    return None if at < 0 else set(re.findall(r"\$\{(\w+)\}", head[at:]))


def code(text: str) -> str:
    """The commands without comments (a # outside quotes starts one, as LIGGGHTS reads it)."""
    kept = []
    for line in text.splitlines():
        quote = ""
        for k, char in enumerate(line):
            if quote:
                quote = "" if char == quote else quote
            elif char in "'\"":
                quote = char
            elif char == "#":
                line = line[:k]
                break
        kept.append(line)
    return "\n".join(kept)


def read_not_defined(text: str) -> set[str]:
    commands = code(text)
    reads = set(re.findall(r"\$\{(\w+)\}", commands)) | set(re.findall(r"(?<![\w])v_(\w+)", commands))
    defines = set(re.findall(r"(?<![\w$])variable\s+(\w+)\s", commands))
    if re.search(r"^\s*include\s+\$\{mesh_dir\}/" + re.escape(MACHINE_FILE), commands, re.MULTILINE):
        defines |= set(machine_values())     # the meshes' machine.in defines the machine geometry
    return reads - defines


@pytest.mark.parametrize("path", INCLUDES, ids=[p.name for p in INCLUDES])
def test_requires_lists_what_the_include_reads(path: Path) -> None:
    text = path.read_text()
    listed = required(text)
    needed = read_not_defined(text)
    if listed is None:
        assert not needed, f"{path.name} has no 'Requires' line but reads {sorted(needed)}"
        return
    assert listed == needed, (f"{path.name}: 'Requires' lists {sorted(listed - needed)} that it does not read, "
                              f"omits {sorted(needed - listed)} that it reads")


def test_the_check_sees_a_wrong_list() -> None:
    # the parsing itself: a list that omits a read variable, and one that names an unread one
    text = "# Requires ${a}.\nvariable b equal ${a}+v_c  # ${d} in a comment is no read\nprint \"${b}\"\n"
    assert required(text) == {"a"} and read_not_defined(text) == {"a", "c"}
