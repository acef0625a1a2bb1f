"""Spec grammar: the shipped configurations, and errors that name the token at fault."""
from __future__ import annotations

import subprocess
import sys
from fractions import Fraction

import pytest

from tsg_meshes.build import resolve_config
from tsg_meshes.spec import SpecError, parse_spec, read_spec


def spec(elements: str, ends: str = "periodic") -> str:
    return f"name test\nends {ends}\nelements {elements}\n"


def test_full_configuration_layout():
    full = read_spec(resolve_config("consigma1-full"))
    assert full.length_mm == 500
    kinds = [e.kind for e in full.elements]
    assert kinds == ["conveying"] * 10 + ["kneading"] * 6 + ["conveying"] + ["kneading"] * 6 + ["conveying"] + ["chopping"] * 2
    block = [e for e in full.elements if e.kind == "kneading"][:6]
    assert all(e.length_mm == Fraction(25, 4) for e in block)
    # reverse stagger: each disc turned 60 deg further with the rotation (omega > 0 about +x)
    assert [b.phase_start_deg - a.phase_start_deg for a, b in zip(block, block[1:])] == [60] * 5
    assert [e.length_mm for e in full.elements if e.kind == "chopping"] == [Fraction(25, 6)] * 2
    conveying = [e for e in full.elements if e.kind == "conveying"]
    # conveying turns against the rotation going downstream: 360 deg less per lead
    assert all(e.phase_end_deg - e.phase_start_deg == -360 * e.length_mm / 25 for e in conveying)
    assert {e.length_mm for e in conveying} == {Fraction(50, 3), 25, Fraction(75, 2)}


def test_periodic_configuration_closes():
    periodic = read_spec(resolve_config("consigma1-periodic"))
    assert periodic.ends == "periodic"
    assert (periodic.elements[-1].phase_end_deg - periodic.elements[0].phase_start_deg) % 180 == 0
    assert [e.kind for e in periodic.elements].count("kneading") == 6


def test_repeat_and_fractions():
    layout = parse_spec(spec("2*C1.5 C1/3 K2x90F", ends="inlet-wall"))
    assert [e.token for e in layout.elements] == ["C1.5", "C1.5", "C1/3", "K2x90F", "K2x90F"]
    assert layout.length_mm == 75 + Fraction(25, 3) + Fraction(25, 2)


@pytest.mark.parametrize("elements, token, message", [
    ("C1 X3 C1", "X3", "unknown element code"),
    ("C1 K6x60Q", "K6x60Q", "unknown element code"),
    ("C-1.5 K6x60R C7/6", "C-1.5", "must be positive"),
    ("C0 C1", "C0", "must be positive"),
    ("C1 K6x10R C1", "K6x10R", "less than 25 deg from a multiple of 180 deg"),
    ("C1 K6x160F C1", "K6x160F", "less than 25 deg from a multiple of 180 deg"),
    ("C1 K6x60 C1", "K6x60", "needs a direction"),
    ("C1 K6 C1", "K6", "need a stagger"),
    ("C1 K6x60R C1", "K6x60R", "does not close"),
    ("C1.5 K6x60R C1.5", "K6x60R", "does not close"),
    ("C1 C1/3", "C1/3", "does not close"),
])
def test_bad_tokens_are_named(elements, token, message):
    with pytest.raises(SpecError) as error:
        parse_spec(spec(elements))
    assert f"'{token}'" in str(error.value) and message in str(error.value)


@pytest.mark.parametrize("text, message", [
    ("name a\nends periodic\n", "no elements"),
    ("name a\nends sideways\nelements C1\n", "unknown ends 'sideways'"),
    ("name a\nends periodic\nscrews C1\n", "unknown key 'screws'"),
    ("ends periodic\nelements C1\n", "'name' needs exactly one value"),
])
def test_bad_lines_are_named(text, message):
    with pytest.raises(SpecError, match=message):
        parse_spec(text)


def test_cli_reports_spec_errors(tmp_path):
    bad = tmp_path / "bad.spec"
    bad.write_text(spec("C1 K6x60R C-2"))
    run = subprocess.run([sys.executable, "-m", "tsg_meshes", "build", str(bad), str(tmp_path / "out")],
                         capture_output=True, text=True)
    assert run.returncode == 2
    assert "token 'C-2'" in run.stderr and "must be positive" in run.stderr
    assert not (tmp_path / "out").exists()
