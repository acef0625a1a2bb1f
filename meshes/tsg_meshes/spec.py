"""Screw-configuration spec files: grammar, parsing, and the element layout (positions and phases).

Lengths and angles are kept as exact fractions (millimetres, degrees) so that phase matching at
periodic ends and between elements is decided exactly, not up to rounding.

Phase convention: theta is the angle of screw 1's tip 0 about +x, measured from +y towards +z.
The screws rotate with omega > 0 about +x (ROTATION_SENSE); a conveying element then has to turn
*against* the rotation going downstream (theta decreases with x) to push material towards +x, see
meshes/README.md.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import numpy as np

ROTATION_SENSE = +1  # sign of omega about +x assumed by the meshes (fix move/mesh ... axis 1 0 0 period > 0)
KNEADING_DISC_MM = Fraction(25, 4)  # D / 4
CHOPPING_ELEMENT_MM = Fraction(25, 6)  # D / 6
LEAD_MM = Fraction(25)
HALF_TURN = Fraction(180)
ENDS = ("periodic", "inlet-wall")
MIN_STAGGER_DEG = Fraction(25)  # smallest disc stagger (mod 180 deg) with well-shaped faces, see _stagger

_NUMBER = r"[-+]?\d+(?:\.\d+)?(?:/\d+)?"
_CONVEYING = re.compile(rf"C(?P<leads>{_NUMBER})")
_DISCS = re.compile(rf"(?P<code>K|CH)(?P<count>{_NUMBER})?(?:x(?P<stagger>{_NUMBER})(?P<direction>[FR])?)?")
_REPEAT = re.compile(r"(?P<times>\d+)\*(?P<token>\S+)")


class SpecError(ValueError):
    """A screw-configuration spec that cannot be built; the message names the offending token."""


@dataclass(frozen=True)
class Element:
    """One zone of the screw: a conveying element or a single kneading / chopping disc."""

    index: int  # 1-based, upstream to downstream
    kind: str  # "conveying" | "kneading" | "chopping"
    token: str  # the spec token it came from, e.g. "K6x60R"
    x_start_mm: Fraction
    x_end_mm: Fraction
    phase_start_deg: Fraction  # screw 1; screw 2 adds 360 / (2 Z)
    phase_end_deg: Fraction

    @property
    def length_mm(self) -> Fraction:
        return self.x_end_mm - self.x_start_mm

    @property
    def twisted(self) -> bool:
        return self.phase_end_deg != self.phase_start_deg

    def phase_at(self, x: np.ndarray) -> np.ndarray:
        """Screw-1 phase (radians) of this element's section at axial positions x (metres)."""
        fraction = (np.asarray(x) - float(self.x_start_mm) / 1000) / (float(self.length_mm) / 1000)
        start, end = np.radians(float(self.phase_start_deg)), np.radians(float(self.phase_end_deg))
        return start + (end - start) * fraction


@dataclass(frozen=True)
class ScrewConfiguration:
    name: str
    ends: str  # "periodic": open screws and barrel, phase-matched ends; "inlet-wall": see README
    tokens: tuple[str, ...]
    elements: tuple[Element, ...]

    @property
    def length_mm(self) -> Fraction:
        return self.elements[-1].x_end_mm

    @property
    def staggers_deg(self) -> tuple[Fraction, ...]:
        """Phase jumps (mod 180 degrees, non-zero) between consecutive elements."""
        jumps = {(b.phase_start_deg - a.phase_end_deg) % HALF_TURN
                 for a, b in zip(self.elements, self.elements[1:])}
        return tuple(sorted(jump for jump in jumps if jump != 0))


def parse_spec(text: str, source: str = "<spec>") -> ScrewConfiguration:
    """Parse a spec (see meshes/README.md). Raises SpecError naming the token or line at fault."""
    fields: dict[str, list[str]] = {"name": [], "ends": [], "elements": []}
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        key, _, value = line.partition(" ")
        if key not in fields:
            raise SpecError(f"{source}:{number}: unknown key '{key}' (expected one of: {', '.join(fields)})")
        fields[key].extend(value.split())
    for key in ("name", "ends"):
        if len(fields[key]) != 1:
            raise SpecError(f"{source}: '{key}' needs exactly one value, got {fields[key] or 'none'}")
    ends = fields["ends"][0]
    if ends not in ENDS:
        raise SpecError(f"{source}: unknown ends '{ends}' (expected one of: {', '.join(ENDS)})")
    if not fields["elements"]:
        raise SpecError(f"{source}: no elements")
    return layout(fields["name"][0], ends, expand_repeats(fields["elements"]))


def read_spec(path: Path | str) -> ScrewConfiguration:
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as problem:
        line = path.read_bytes()[:problem.start].count(b"\n") + 1
        raise SpecError(f"{path}:{line}: not a text spec file (byte {problem.object[problem.start]:#04x} "
                        f"at offset {problem.start} is not UTF-8)") from None
    except IsADirectoryError:
        raise SpecError(f"{path}: is a directory, not a spec file") from None
    return parse_spec(text, source=str(path))


def expand_repeats(tokens: list[str]) -> tuple[str, ...]:
    expanded: list[str] = []
    for token in tokens:
        repeat = _REPEAT.fullmatch(token)
        if repeat:
            if int(repeat["times"]) < 1:
                raise SpecError(f"token '{token}': repeat count must be at least 1")
            expanded.extend([repeat["token"]] * int(repeat["times"]))
        else:
            expanded.append(token)
    return tuple(expanded)


def layout(name: str, ends: str, tokens: tuple[str, ...]) -> ScrewConfiguration:
    """Place the elements along x from 0 and give each its phase: every element starts at the
    phase where the previous one ends; within a disc block each disc is staggered from the last."""
    elements: list[Element] = []
    token_phase_changes: list[tuple[str, Fraction]] = []
    x, phase = Fraction(0), Fraction(0)
    for token in tokens:
        token_start_phase = phase
        for kind, length, phase_change, disc_phase in _element_pieces(token):
            start_phase = phase + disc_phase
            end_phase = start_phase + phase_change
            elements.append(Element(len(elements) + 1, kind, token, x, x + length, start_phase, end_phase))
            x, phase = x + length, end_phase
        token_phase_changes.append((token, phase - token_start_phase))
    if ends == "periodic":
        _check_periodic_closure(name, token_phase_changes)
    return ScrewConfiguration(name, ends, tokens, tuple(elements))


def _element_pieces(token: str):
    """Yield (kind, length_mm, phase change along the piece, phase jump before it) per zone."""
    conveying = _CONVEYING.fullmatch(token)
    discs = _DISCS.fullmatch(token)
    if conveying and not token.startswith("CH"):
        leads = _positive(conveying["leads"], token, "conveying length (in leads)")
        yield "conveying", leads * LEAD_MM, -ROTATION_SENSE * 360 * leads, Fraction(0)
        return
    if discs:
        kind, thickness = (("kneading", KNEADING_DISC_MM) if discs["code"] == "K"
                           else ("chopping", CHOPPING_ELEMENT_MM))
        count = _positive(discs["count"], token, "disc count") if discs["count"] else Fraction(1)
        if count.denominator != 1:
            raise SpecError(f"token '{token}': disc count must be a whole number")
        stagger = _stagger(discs, token, count)
        for k in range(int(count)):
            yield kind, thickness, Fraction(0), (stagger if k else Fraction(0))
        return
    raise SpecError(f"token '{token}': unknown element code (expected C<leads>, K<n>x<angle><F|R>, "
                    f"CH[<n>x<angle><F|R>], or <n>*<token>)")


def _positive(text: str, token: str, what: str) -> Fraction:
    try:
        value = Fraction(text)
    except ZeroDivisionError:
        raise SpecError(f"token '{token}': {what} {text} divides by zero (a fraction p/q needs q > 0)") from None
    if value <= 0:
        raise SpecError(f"token '{token}': {what} must be positive, got {text}")
    return value


def _stagger(discs: re.Match, token: str, count: Fraction) -> Fraction:
    """Signed phase step between discs: reverse stagger steps with the rotation, forward against it."""
    if discs["stagger"] is None:
        if count > 1:
            raise SpecError(f"token '{token}': {int(count)} discs need a stagger, e.g. {discs['code']}{int(count)}x60R")
        return Fraction(0)
    if discs["direction"] is None:
        raise SpecError(f"token '{token}': stagger needs a direction, F (forward) or R (reverse)")
    angle = Fraction(discs["stagger"])
    if angle < 0:
        raise SpecError(f"token '{token}': stagger angle must not be negative (use F or R for the direction)")
    step = angle if discs["direction"] == "R" else -angle
    step *= ROTATION_SENSE
    # Two discs staggered by a small angle expose thin crescent faces to each other whose tips are
    # as sharp as the angle at which the two profiles cross (about a third of the stagger, and
    # tangent below the tip angle, 13.6 deg): below MIN_STAGGER_DEG the faces' triangles get
    # smaller than 5 degrees (measured), at 15-18 deg LIGGGHTS-rejectable slivers or no mesh at all.
    residue = step % HALF_TURN
    if residue != 0 and not MIN_STAGGER_DEG <= residue <= HALF_TURN - MIN_STAGGER_DEG:
        raise SpecError(f"token '{token}': stagger {float(angle):g} deg is less than {MIN_STAGGER_DEG} deg "
                        f"from a multiple of 180 deg, so the faces between the discs would taper into "
                        f"slivers; use 0 or a stagger in [{MIN_STAGGER_DEG}, {HALF_TURN - MIN_STAGGER_DEG}] deg")
    return step


def _check_periodic_closure(name: str, token_phase_changes: list[tuple[str, Fraction]]) -> None:
    mismatch = sum(change for _, change in token_phase_changes) % HALF_TURN
    if mismatch == 0:
        return
    culprits = ", ".join(f"'{token}' {float(change):+g} deg" for token, change in token_phase_changes
                         if change % HALF_TURN)
    raise SpecError(
        f"{name}: periodic screw does not close: the outlet phase differs from the inlet phase by "
        f"{float(mismatch):g} deg mod 180 deg; tokens whose phase change is not a multiple of 180 deg: "
        f"{culprits}. Change a conveying length or a stagger so that the total is a multiple of 180 deg")
