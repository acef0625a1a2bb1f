"""Lint of the Python packages (configuration in pyproject.toml): ruff and mypy, failing on any finding."""
import os
import subprocess
import sys
from pathlib import Path

SOURCE = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def run(*tool: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", *tool], cwd=SOURCE, capture_output=True, text=True, timeout=600)


def test_ruff_finds_nothing() -> None:
    proc = run("ruff", "check", "--no-cache", "--output-format", "concise")
    assert proc.returncode == 0, proc.stdout[-5000:] + proc.stderr[-2000:]


def test_mypy_finds_nothing() -> None:
    proc = run("mypy", "--no-incremental", "--cache-dir", os.devnull)
    assert proc.returncode == 0, proc.stdout[-5000:] + proc.stderr[-2000:]
