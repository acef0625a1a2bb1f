"""The inputs run as typed (issue 17 item 1): after ./tsg setup, `cd cases && mpirun -np N lmp -in
in.tsg_periodic` runs the seed paper's periodic reference with the case file's defaults - 400 um
particles, the 1 um meshes, the 2.7 g fill set-up made - here for a few hundred steps (-var times)
on 1 and 2 ranks; only the output folder is moved out of runs/ (a test must not overwrite a user's
run)."""
import os
import re
import subprocess
from pathlib import Path

import pytest

from tsg_analysis.liggghts_log import parse_thermo

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
LMP = os.environ.get("TSG_LMP", str(ROOT / "build" / "lmp"))
FILL = ROOT / "build" / "prepared" / "periodic-fill.in"


@pytest.mark.parametrize("ranks", [2])   # as a cluster user types it; one rank costs the same set-up again
def test_periodic_reference_runs_as_typed(tmp_path, ranks):
    assert FILL.is_file() and FILL.with_name(FILL.name + ".data").is_file(), \
        f"{FILL} is missing: ./tsg setup makes it (step 'paper-scale inputs of the case files')"
    prefix = [os.environ.get("TSG_MPIEXEC", "mpirun"), "-np", "2", "--oversubscribe", "--allow-run-as-root"] if ranks == 2 else []
    # 50 us of start-up and 50 us of sampling at 0.498 us a step (about 100 + 100 steps), a thermo row every 50
    command = prefix + [LMP, "-in", "in.tsg_periodic", "-var", "out_dir", str(tmp_path), "-var", "t_startup", "5e-5",
                        "-var", "t_sample", "5e-5", "-var", "thermo_every", "50"]
    proc = subprocess.run(command, cwd=ROOT / "cases", capture_output=True, text=True, timeout=1200,
                          env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    log = (tmp_path / "log.lammps").read_text(errors="replace")
    assert proc.returncode == 0, log[-3000:] + proc.stderr[-2000:]
    # the paper's values: the TSG-PARAMETERS line and the meshes the defaults name
    parameters = dict(word.split("=", 1) for word in re.search(r"^TSG-PARAMETERS (.*)$", log, re.M).group(1).split())
    assert parameters["d_mean"] == "0.0004" and parameters["dt_fraction"] == "0.1" and parameters["rpm"] == "600"
    assert parameters["gravity"] == "9.81"
    assert parameters["mus_pp"] == parameters["mus_pg"] == "0.5" and parameters["e_pp"] == parameters["e_pg"] == "0.5"
    assert parameters["mesh_dir"].endswith("build/meshes/consigma1-periodic-1um")
    count = int(re.search(r"variable fill_count equal (\d+)", FILL.read_text()).group(1))
    mass_g = float(re.search(r"# ([\d.]+) g at rho_p", FILL.read_text()).group(1))
    assert 2.7 <= mass_g < 2.71 and count > 60000                   # the paper's hold-up (its particle counts) of 400 um
    thermo = parse_thermo(log)
    # the plan is in time: the run ends at the step nearest to t_startup + t_sample = 100 us
    dt = float(re.search(r"^check/contact: critical step estimate \S+ s \(.*?\); time step (\S+) s", log, re.M).group(1))
    assert 4.9e-7 < dt < 5.0e-7                                       # 0.1 of the Rayleigh time of 400 um particles
    assert thermo[-1]["Step"][-1] == round(1e-4 / dt)
    assert thermo[-1]["Atoms"][-1] == count and thermo[-1]["escaped"][-1] == 0
    assert f"TSG-DONE escaped 0 particles {count}" in log
    for name in ("residence.txt", "massflow.txt", "elements.txt"):
        assert (tmp_path / name).is_file(), name                      # outputs in out_dir, none in cases/
    assert not any((ROOT / "cases" / name).exists() for name in ("residence.txt", "massflow.txt", "elements.txt"))


def test_periodic_reference_runs_past_its_first_squeezes(tmp_path):
    """The paper's machine squeezes its 400 um particles between the screws from about 2 ms on (its
    gap between conveying flights, 0.18 mm, is narrower than every particle): with the case file's
    defaults the squeezes are counted by the ledger and the run reaches its end; the overlaps it
    reaches are deeper than the demo's overlap guard (0.5 R at 6 ms here) allows."""
    command = [os.environ.get("TSG_MPIEXEC", "mpirun"), "-np", "2", "--oversubscribe", "--allow-run-as-root", LMP,
               "-in", "in.tsg_periodic", "-var", "out_dir", str(tmp_path), "-var", "t_startup", "0",
               "-var", "t_sample", "0.006", "-var", "thermo_every", "1000"]
    proc = subprocess.run(command, cwd=ROOT / "cases", capture_output=True, text=True, timeout=1500,
                          env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    log = (tmp_path / "log.lammps").read_text(errors="replace")
    assert proc.returncode == 0 and "ERROR" not in log, log[-3000:] + proc.stderr[-2000:]
    assert "TSG-SQUEEZE the gaps between the screws are narrower" in log
    ledger = dict(zip(*[iter(re.search(r"^TSG-SQUEEZES (.*)$", log, re.M).group(1).replace(" m/s", "")
                             .replace(" J", "").split())] * 2))
    assert float(ledger["events"]) >= 10 and float(ledger["distinct_particles"]) >= 10, ledger
    assert float(ledger["peak_wall_overlap"]) > 0.3, ledger
    assert float(ledger["crossings"]) == 0 and float(ledger["energy_excess"]) < 0, ledger
    records = [line for line in (tmp_path / "squeezes.txt").read_text().splitlines() if not line.startswith("#")]
    assert len(records) == int(float(ledger["events"]))
    assert re.search(r"^TSG-DONE escaped 0 particles \d+", log, re.M)


def test_merged_feed_blocks_cover_exactly_the_free_cubes():
    import numpy as np

    from tsg_cases.prepared import merge_cubes
    rng = np.random.default_rng(7)
    side = 0.5
    cells = np.argwhere(rng.random((9, 7, 5)) < 0.6)            # a grid of free cubes with holes
    corners = cells * side + np.array([0.1, -2.0, 3.0])
    blocks = merge_cubes(corners, side)
    assert len(blocks) < len(corners)
    centres = corners + side / 2
    free = {tuple(c) for c in cells}
    holes = np.array([c for c in np.argwhere(np.ones((9, 7, 5), dtype=bool)) if tuple(c) not in free]) * side \
        + np.array([0.1, -2.0, 3.0]) + side / 2

    def hits(points):
        return np.array([[np.all((q > lo) & (q < hi)) for lo, hi in blocks] for q in points]).sum(axis=1)
    assert np.all(hits(centres) == 1)                             # every free cube in exactly one block
    assert np.all(hits(holes) == 0)                               # no block covers a cube that is not free
    assert sum(np.prod(hi - lo) for lo, hi in blocks) == pytest.approx(len(corners) * side ** 3)


def test_nonperiodic_subdomain_runs_as_typed(tmp_path):
    # the paper's non-periodic sub-domain with its defaults (400 um, 1 um meshes, EEPA, fed at the
    # inlet from the feed blocks set-up made) for 1e-4 s: particles are generated and none escapes
    feed = ROOT / "build" / "prepared" / "nonperiodic-feed.in"
    assert feed.is_file(), f"{feed} is missing: ./tsg setup makes it (step 'paper-scale inputs of the case files')"
    proc = subprocess.run([LMP, "-in", "in.tsg_nonperiodic", "-var", "out_dir", str(tmp_path), "-var", "t_run", "1e-4",
                           "-var", "thermo_every", "50"], cwd=ROOT / "cases", capture_output=True, text=True, timeout=1200,
                          env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    log = (tmp_path / "log.lammps").read_text(errors="replace")
    assert proc.returncode == 0, log[-3000:] + proc.stderr[-2000:]
    inserted = int(re.search(r"inserted (\d+) particle templates", log).group(1))
    thermo = parse_thermo(log)
    assert inserted > 1000 and thermo[-1]["Atoms"][-1] == inserted and thermo[-1]["escaped"][-1] == 0
    assert "cohesion=1" in log and "mesh_dir=./../build/meshes/consigma1-nonperiodic-1um" in log
    assert f"TSG-DONE escaped 0 particles {inserted}" in log
