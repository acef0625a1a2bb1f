"""Axial sections of the built meshes, in every element type, against Tables 1-2 (within 0.5 %)."""
from __future__ import annotations

from fractions import Fraction

import pytest

from conftest import SHIPPED
from tsg_meshes.analysis import perimeter, section_segments, signed_area
from tsg_meshes.profile import TwinBore

SCREW_AREA = 242.37e-6
SCREW_PERIMETER = 59.56e-3
BORE_AREA = 920.0e-6
FREE_AREA = 435.26e-6
FREE_FRACTION = 0.4731
RELATIVE = 0.005

# fractions of an element's length with prime numerators: off every screw plane k/n of an element
# (n < 10000); section_segments refuses a plane through a vertex anyway
WHERE = (Fraction(2137, 10000), Fraction(6271, 10000))


def section_positions(configuration):
    """Two positions in the first and the last element of each kind."""
    positions = []
    for kind in ("conveying", "kneading", "chopping"):
        elements = [e for e in configuration.elements if e.kind == kind]
        for element in dict.fromkeys([elements[0], elements[-1]] if elements else []):
            for fraction in WHERE:
                x = float(element.x_start_mm + element.length_mm * fraction) / 1000
                positions.append((kind, element.index, x))
    return positions


@pytest.mark.parametrize("name", SHIPPED)
def test_sections_match_tables(build, name):
    geometry = build(name)
    kinds_seen = set()
    for kind, index, x in section_positions(geometry.configuration):
        kinds_seen.add(kind)
        screws = [section_segments(mesh.corners, x) for mesh in geometry.screws]
        bore = section_segments(geometry.barrel.corners, x)
        where = f"{name}, {kind} element {index}, x = {x * 1e3:.3f} mm"
        for screw in screws:
            assert signed_area(screw) == pytest.approx(SCREW_AREA, rel=RELATIVE), where
            assert perimeter(screw) == pytest.approx(SCREW_PERIMETER, rel=RELATIVE), where
        # the barrel's normals face into the bore, so its section runs clockwise
        bore_area = -signed_area(bore)
        free = bore_area - sum(signed_area(screw) for screw in screws)
        assert bore_area == pytest.approx(BORE_AREA, rel=RELATIVE), where
        assert perimeter(bore) == pytest.approx(TwinBore().perimeter_formula(), rel=RELATIVE), where
        assert free == pytest.approx(FREE_AREA, rel=RELATIVE), where
        assert free / bore_area == pytest.approx(FREE_FRACTION, rel=RELATIVE), where
    assert "conveying" in kinds_seen and "kneading" in kinds_seen
    if name == "consigma1-full":
        assert "chopping" in kinds_seen
