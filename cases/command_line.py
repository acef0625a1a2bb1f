"""What the case tools' command lines share: the parser and the one-line error on a bad input."""
from __future__ import annotations

import argparse
import sys
from typing import Callable, Mapping


def command_parser(prog: str, description: str | None,
                   commands: Mapping[str, str]) -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    """A parser that keeps the module docstring's layout and takes --debug, with one sub-parser per
    command (name: help); args.command names the one given."""
    parser = argparse.ArgumentParser(prog=prog, description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--debug", action="store_true", help="show the Python traceback of an error")
    sub = parser.add_subparsers(dest="command", required=True)
    return parser, {name: sub.add_parser(name, help=text) for name, text in commands.items()}


def run_reporting(prog: str, action: Callable[[], int], expected: tuple[type[Exception], ...], debug: bool) -> int:
    """action(); an expected error becomes "<prog>: error: <message>" and exit status 2 (with --debug: the traceback)."""
    try:
        return action()
    except expected as problem:
        if debug:
            raise
        print(f"{prog}: error: {problem}", file=sys.stderr)
        return 2
