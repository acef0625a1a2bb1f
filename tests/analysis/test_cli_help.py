"""Every command the project installs (pyproject.toml [project.scripts]) and every one of its
sub-commands prints its help and exits 0: argparse formats help text lazily, so a stray '%' in a
help string (read as a format directive) only shows as a crash of `--help`."""
import importlib
import re
import tomllib
from pathlib import Path

import pytest

PYPROJECT = Path(__file__).resolve().parents[2] / "pyproject.toml"
SCRIPTS = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["project"]["scripts"]


def _help(entry: str, argv: list[str], capsys) -> str:
    module, function = entry.split(":")
    main = getattr(importlib.import_module(module), function)
    with pytest.raises(SystemExit) as stop:
        main([*argv, "--help"])
    captured = capsys.readouterr()
    assert stop.value.code == 0, f"{entry} {argv} --help exited {stop.value.code}: {captured.err}"
    assert captured.out.startswith("usage:"), captured.out[:200]
    return captured.out


def test_the_scripts_are_listed():
    assert {"tsg-run-case", "tsg-sweep", "tsg-analysis", "tsg-meshes"} <= set(SCRIPTS)


@pytest.mark.parametrize("name", sorted(SCRIPTS))
def test_help_of_every_command_and_subcommand(name, capsys):
    choices = re.search(r"^\s*\{([\w,-]+)\}", _help(SCRIPTS[name], [], capsys), flags=re.MULTILINE)
    subcommands = choices.group(1).split(",") if choices else []
    if name == "tsg-analysis":  # the command whose sub-commands once crashed on '--help'
        assert {"summary", "compare", "domains"} <= set(subcommands)
    for sub in subcommands:
        _help(SCRIPTS[name], [sub], capsys)
