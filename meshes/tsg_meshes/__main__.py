"""Command line: python -m tsg_meshes build <config> <outdir> [--tolerance M] [--clearance M] [--screw-clearance M] [--disc-gap M]
| build-all <outdir> | render <imgdir>."""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from typing import Callable

from .build import DEFAULT_TOLERANCE, MAX_TOLERANCE, MeshQualityError, build_all, generate, resolve_config, write_geometry
from .profile import MAX_CLEARANCE, profile_for_clearance
from .spec import read_spec


def length_up_to(largest: float) -> Callable[[str], float]:
    """An argparse type: a length in m, 0 < value <= largest."""
    def parse_length(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text} is not a number (a length in m)") from None
        if not 0 < value <= largest:
            raise argparse.ArgumentTypeError(f"{text} m is outside (0, {largest:g}] m")
        return value
    return parse_length


tolerance = length_up_to(MAX_TOLERANCE)
clearance = length_up_to(MAX_CLEARANCE)


class OutputError(OSError):
    """An output directory that cannot be written."""


def check_output_dir(path: Path) -> None:
    """Before any work: the output directory must be (or become) a writable directory."""
    for parent in (path, *path.parents):
        if parent.exists():
            if not parent.is_dir():
                raise OutputError(f"output directory {path}: {parent} is a file, not a directory")
            if not os.access(parent, os.W_OK | os.X_OK):
                raise OutputError(f"output directory {path}: {parent} is not writable")
            return


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tsg_meshes", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    build = commands.add_parser("build", help="build one configuration into <outdir>")
    build.add_argument("config", help="spec file, or the name of a shipped config (meshes/configs/<name>.spec)")
    build.add_argument("outdir", type=Path)
    build.add_argument("--tolerance", type=tolerance, default=DEFAULT_TOLERANCE,
                       help=f"largest chordal deviation from the exact surface, metres (default {DEFAULT_TOLERANCE:g})")
    build.add_argument("--clearance", type=clearance,
                       help="flight-tip/barrel gap, metres, with the same barrel and centre distance (smaller "
                            "screws); default: the paper's machine, 0.44 mm")
    build.add_argument("--screw-clearance", type=clearance,
                       help="tip/root gap between the screws in an axial section, metres (default: --clearance "
                            "if given, else the paper's 0.35 mm)")
    build.add_argument("--disc-gap", type=clearance, default=0.0,
                       help="axial spacer between staggered discs, metres (default 0: the discs touch, as in "
                            "the paper's machine)")
    everything = commands.add_parser("build-all", help="build every shipped configuration into <outdir>/<name>-<tol>um/")
    everything.add_argument("outdir", type=Path)
    render = commands.add_parser("render", help="PNG renders of element types and assembled screws")
    render.add_argument("imgdir", type=Path)
    parser.add_argument("--debug", action="store_true", help="show the Python traceback of an error")
    args = parser.parse_args(argv)

    started = time.perf_counter()
    try:
        for name in ("outdir", "imgdir"):
            target = getattr(args, name, None)
            if target is not None:
                check_output_dir(target)
        if args.command == "build":
            geometry = generate(read_spec(resolve_config(args.config)), args.tolerance,
                                profile_for_clearance(args.clearance, args.screw_clearance), args.disc_gap)
            written = write_geometry(geometry, args.outdir)
        elif args.command == "build-all":
            written = build_all(args.outdir)
        else:
            from .render import render_all  # pyvista is only needed here
            written = render_all(args.imgdir)
    except (ValueError, MeshQualityError, OSError) as error:   # SpecError is a ValueError
        if args.debug:
            raise
        print(f"tsg_meshes: error: {error}", file=sys.stderr)
        return 2
    for path in written:
        print(path)
    print(f"done in {time.perf_counter() - started:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
