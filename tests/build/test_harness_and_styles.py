"""The harness catches what it must, our styles are registered, errors survive redirected output."""
import os
import re
import subprocess
from pathlib import Path

import pytest

from tsg_harness import LmpFailed, lmp_executable, run_lmp

SOURCE = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
BUILD = Path(os.environ.get("TSG_BUILD_DIR", SOURCE / "build"))
OVERLAY = SOURCE / "src-liggghts-eepa"
BED = (Path(__file__).parent / "inputs" / "in.settle_bed").read_text()

STYLE_MACROS = {  # macro in our headers -> heading of its section in `lmp -h`
    "FixStyle": "Fix styles", "ComputeStyle": "Compute styles", "PairStyle": "Pair styles",
    "NORMAL_MODEL": "Normal models", "TANGENTIAL_MODEL": "Tangential models",
    "COHESION_MODEL": "Cohesion models", "ROLLING_MODEL": "Rolling models", "DumpStyle": "Dump styles",
    "CommandStyle": "Command styles",
}


def our_styles() -> list[tuple[str, str]]:
    found = []
    for header in sorted(OVERLAY.rglob("*.h")):
        for macro, section in STYLE_MACROS.items():
            for match in re.finditer(rf"^{macro}\((?:[A-Z0-9_]+,\s*)?([\w/]+)\s*[,)]", header.read_text(), re.M):
                found.append((section, match.group(1)))
    return found


def help_sections() -> dict[str, set[str]]:
    # LIGGGHTS exits with status 1 after printing its help: judge the text, not the status
    text = subprocess.run([lmp_executable(), "-h"], capture_output=True, text=True).stdout
    assert "* Fix styles" in text, "lmp -h printed no style list"
    sections: dict[str, set[str]] = {}
    current = None
    for line in text.splitlines():
        if line.startswith("* "):
            current = line[2:].rstrip(":")
            sections[current] = set()
        elif current:
            sections[current].update(line.split())
    return sections


def test_every_extension_style_is_listed_by_lmp_help():
    styles = our_styles()
    assert styles, f"no style macros found in {OVERLAY}/**/*.h"
    sections = help_sections()
    for section, name in styles:
        matching = [s for s in sections if s.startswith(section)]
        assert matching, f"`lmp -h` has no section '{section}'"
        assert any(name in sections[s] for s in matching), f"{name} missing from '{section}' in `lmp -h`"


def whitelist() -> list[tuple[str, ...]]:
    lines = (OVERLAY / "contact" / "contact_models.list").read_text().splitlines()
    return [tuple(p.strip() for p in m.group(1).split(","))
            for m in (re.match(r"GRAN_MODEL\((.*)\)", l) for l in lines) if m]


def model_keywords() -> dict[str, str]:
    """Model id (HERTZ, ROLLING_CDT, ...) -> input keyword, read from the registration macros."""
    keywords = {"TANGENTIAL_OFF": "off", "COHESION_OFF": "off", "ROLLING_OFF": "off"}
    for header in list((BUILD / "liggghts" / "src").glob("*_model_*.h")) + list(OVERLAY.rglob("*_model_*.h")):
        for m in re.finditer(r"^[A-Z]+_MODEL\(([A-Z0-9_]+),\s*([\w/]+),", header.read_text(), re.M):
            keywords[m.group(1)] = m.group(2)
    return keywords


STOCK_PROPERTIES = {"COHESION_SJKR": "fix m5 all property/global cohesionEnergyDensity peratomtypepair 1 1000\n",
                    "ROLLING_CDT": "fix m6 all property/global coefficientRollingFriction peratomtypepair 1 0.01\n"}


@pytest.mark.parametrize("combination", [c for c in whitelist() if c[0] in ("HERTZ", "HOOKE")],
                         ids=lambda c: "-".join(c[:4]))
def test_whitelisted_stock_combination_runs_on_the_fast_path(tmp_path, combination):
    normal, tangential, cohesion, rolling, _surface = combination
    kw = model_keywords()
    model = f"model {kw[normal]} tangential {kw[tangential]}"
    if cohesion != "COHESION_OFF":
        model += f" cohesion {kw[cohesion]}"
    if rolling != "ROLLING_OFF":
        model += f" rolling_friction {kw[rolling]}"
    text = BED.replace("model hertz tangential history", model)
    extra = "".join(STOCK_PROPERTIES.get(c, "") for c in combination)
    text = text.replace("pair_style gran", extra + "pair_style gran", 1)
    if normal == "HOOKE":
        text = text.replace("pair_coeff * *", "pair_coeff * *\nfix m7 all property/global characteristicVelocity scalar 0.5", 1)
    run = run_lmp(text, tmp_path, variables={"nsteps": 20})
    run.assert_clean()


def test_harness_rejects_the_contact_model_slow_path(tmp_path):
    # hertz + sjkr2 is deliberately not compiled: LIGGGHTS falls back to its generic path and warns
    text = BED.replace("pair_style gran model hertz tangential history",
                       "fix m5 all property/global cohesionEnergyDensity peratomtypepair 1 1000\n"
                       "pair_style gran model hertz tangential history cohesion sjkr2")
    run = run_lmp(text, tmp_path, variables={"nsteps": 10})
    with pytest.raises(LmpFailed, match="whitelist"):
        run.assert_clean()


def test_error_message_survives_redirected_output(tmp_path):
    # `include` of a missing file goes through Error::one, which upstream only prints to the
    # (buffered) screen before MPI_Abort; our patch repeats it on stderr and in the log.
    run = run_lmp("units si\ninclude no_such_file.in\n", tmp_path, expect_error=True)
    assert "no_such_file.in" in run.stderr
    assert "no_such_file.in" in run.log
    assert any("no_such_file.in" in e for e in run.errors)


def test_lost_atoms_are_reported_as_failure(tmp_path):
    # remove the floor: particles fall out of the fixed box, which thermo_modify lost error reports
    text = BED.replace("fix zlo all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n", "")
    run = run_lmp(text, tmp_path, variables={"nsteps": 60000}, expect_error=True)
    assert any("Lost atoms" in e for e in run.errors), run.errors
