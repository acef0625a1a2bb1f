"""Clearances measured on mesh sections while both screws co-rotate through 180 degrees (the
profile repeats after 180): barrel-tip 0.44 mm and screw-screw 0.35 mm within 5 %, no overlap."""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from conftest import SHIPPED
from tsg_meshes.analysis import corotation_clearances, section_segments

BARREL_CLEARANCE = 0.44e-3
SCREW_GAP = 0.35e-3
RELATIVE = 0.05
ANGLES = np.radians(np.arange(0.0, 180.0 + 1e-9, 0.5))


@pytest.mark.parametrize("name", SHIPPED)
def test_clearances_under_corotation(build, name):
    geometry = build(name)
    for kind in ("conveying", "kneading", "chopping"):
        elements = [e for e in geometry.configuration.elements if e.kind == kind]
        if not elements:
            continue
        middle = elements[len(elements) // 2]
        x = float(middle.x_start_mm + middle.length_mm * Fraction(4127, 10000)) / 1000
        sections = [section_segments(mesh.corners, x) for mesh in (*geometry.screws, geometry.barrel)]
        result = corotation_clearances(*sections, ANGLES)
        where = f"{name}, {kind} element {middle.index}"
        assert result["clear"].all(), f"{where}: overlap at {np.degrees(ANGLES[~result['clear']])} deg"
        assert result["screw_gap"].min() >= SCREW_GAP * (1 - RELATIVE), where
        assert result["screw_gap"].max() <= SCREW_GAP * (1 + RELATIVE), where
        assert result["barrel_gap"].min() >= BARREL_CLEARANCE * (1 - RELATIVE), where
        assert result["barrel_gap"].max() <= BARREL_CLEARANCE * (1 + RELATIVE), where
