"""The mesh generator's rows of the bad-input campaign (tests/errors/README.md): python -m tsg_meshes."""
from __future__ import annotations

from badinput import BadInput

MESHES = ["{python}", "-m", "tsg_meshes"]


def spec(text: str | bytes) -> dict[str, str | bytes]:
    return {"in.spec": text}


def build(*extra: str) -> list[str]:
    return [*MESHES, "build", "{tmp}/in.spec", "{tmp}/out", *extra]


GOOD = "name t\nends periodic\nelements "

CASES: list[BadInput] = [
    BadInput("meshes.spec.divide-by-zero", ("token 'C1/0'", "divides by zero"),
             why="a fraction with denominator 0 (ZeroDivisionError before)",
             files=spec(GOOD + "C1/0\n"), command=build()),
    BadInput("meshes.spec.binary", ("{tmp}/in.spec:1", "not a text spec file"),
             why="a binary file given as the spec (UnicodeDecodeError before)",
             files=spec(bytes(range(128, 256))), command=build()),
    BadInput("meshes.spec.directory", ("no spec file '{tmp}/in.spec'",),
             why="a directory given as the spec", files={"in.spec/x": "x"}, command=build()),
    BadInput("meshes.spec.unknown-config", ("no spec file 'consigma9'", "consigma1-periodic"),
             why="a configuration name that is not shipped lists the shipped ones",
             command=[*MESHES, "build", "consigma9", "{tmp}/out"]),
    BadInput("meshes.spec.unknown-key", ("in.spec:1", "unknown key 'colour'"),
             why="a key the grammar does not have", files=spec("colour red\n"), command=build()),
    BadInput("meshes.spec.no-elements", ("no elements",), why="a spec without elements",
             files=spec("name t\nends periodic\n"), command=build()),
    BadInput("meshes.spec.empty", ("'name' needs exactly one value, got none",), why="an empty spec file", files=spec(""), command=build()),
    BadInput("meshes.spec.unknown-ends", ("unknown ends 'open'",), why="ends must be one of the known kinds",
             files=spec("name t\nends open\nelements C1\n"), command=build()),
    BadInput("meshes.spec.unknown-token", ("token 'X5'", "unknown element code"),
             why="an element code the grammar does not have", files=spec(GOOD + "X5\n"), command=build()),
    BadInput("meshes.spec.zero-length", ("token 'C0'", "must be positive"),
             why="a conveying element of no length", files=spec(GOOD + "C0\n"), command=build()),
    BadInput("meshes.spec.zero-discs", ("token 'K0x60R'",),
             why="a kneading block of no discs", files=spec(GOOD + "K0x60R\n"), command=build()),
    BadInput("meshes.spec.fractional-discs", ("disc count must be a whole number",),
             why="half a disc", files=spec(GOOD + "K3/2x60R\n"), command=build()),
    BadInput("meshes.spec.repeat-zero", ("repeat count must be at least 1",),
             why="an element repeated zero times", files=spec(GOOD + "0*C1\n"), command=build()),
    BadInput("meshes.spec.key-twice", ("'name' needs exactly one value",),
             why="a key with two values", files=spec("name a b\nends periodic\nelements C1\n"), command=build()),
    BadInput("meshes.out.is-a-file", ("output directory", "is a file, not a directory"),
             why="the output directory is a file (traceback before)", files={**spec(GOOD + "C1\n"), "out": "x\n"},
             command=build(), intact=("out",)),
    BadInput("meshes.out.under-a-file", ("{tmp}/afile is a file, not a directory",),
             why="the output directory lies under a file", files={**spec(GOOD + "C1\n"), "afile": "x\n"},
             command=[*MESHES, "build", "{tmp}/in.spec", "{tmp}/afile/out"], intact=("afile",)),
    BadInput("meshes.tolerance.zero", ("--tolerance", "outside (0,"), why="a mesh of zero chordal tolerance",
             files=spec(GOOD + "C1\n"), command=build("--tolerance", "0")),
    BadInput("meshes.tolerance.coarse", ("--tolerance", "outside (0, 5e-05]"),
             why="coarser meshes turn the faces between staggered discs into slivers",
             files=spec(GOOD + "C1\n"), command=build("--tolerance", "1e-3")),
    BadInput("meshes.tolerance.text", ("--tolerance", "abc is not a number"), why="a tolerance that is not a number",
             files=spec(GOOD + "C1\n"), command=build("--tolerance", "abc")),
    BadInput("meshes.command.unknown", ("invalid choice: 'make'",), why="a sub-command that does not exist",
             command=[*MESHES, "make"]),
]
