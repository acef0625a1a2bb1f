"""-v snapshot 1: particles and screws in their pose at the last step (include/snapshot.in), for the
report's snapshot figure; the measurement outputs are byte-identical to a run without it."""
import math
import re
from pathlib import Path

import pytest

from tsg_analysis.liggghts_log import parse_thermo
from test_cases_smoke import run_case

SHORT = (("t_startup", 0.002), ("t_sample", 0.002), ("stats_every", 200), ("thermo_every", 400))


def last_step_and_time(out: Path) -> tuple[int, float]:
    blocks = [b for b in parse_thermo((out / "log.lammps").read_text()) if "Time" in b and len(b["Time"])]
    return int(blocks[-1]["Step"][-1]), float(blocks[-1]["Time"][-1])


@pytest.mark.parametrize("drive", ["corotating", "stock"])
def test_snapshot_writes_the_last_step_and_changes_no_output(tmp_path, drive):
    with_snapshot, without = tmp_path / "with", tmp_path / "without"
    run_case("periodic", with_snapshot, *SHORT, ("screw_drive", drive), ("snapshot", 1))
    run_case("periodic", without, *SHORT, ("screw_drive", drive))
    for name in ("massflow.txt", "elements.txt", "residence.txt"):
        assert (with_snapshot / name).read_bytes() == (without / name).read_bytes(), name
    assert not (without / "dumps").exists()
    step, time = last_step_and_time(with_snapshot)
    dumps = sorted(p.name for p in (with_snapshot / "dumps").iterdir())
    assert f"particles_{step}.vtk" in dumps
    if drive == "corotating":
        assert {f"screws_{m}_{step}.vtk" for m in ("screw1", "screw2", "barrel")} <= set(dumps)
        # the pose: angle ω t at the last step (600 rpm), from the dump's own header
        header = (with_snapshot / "dumps" / f"screws_screw1_{step}.vtk").read_text().splitlines()[1]
        angle = float(re.search(r"angle (\S+) rad", header).group(1))
        assert angle == pytest.approx(2 * math.pi * 600 / 60 * time, rel=1e-6)
    else:
        assert f"screws_{step}.vtk" in dumps
    assert len([d for d in dumps if d.startswith("particles_") and "boundingBox" not in d]) == 1   # one snapshot only
