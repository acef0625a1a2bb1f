"""Short smoke versions of the granulator cases (demo scale): conveying direction and speed, mass
conservation, no escaped or lost particles, outputs present and parseable, -var changes exactly
the intended parameter, bad input stops with a clear message."""
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tsg_analysis.liggghts_log import parse_thermo
from tsg_analysis.run import Run
from tsg_cases.launcher import lmp_command, lmp_environment

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
PYTHON = sys.executable
LEAD = 0.025            # m, conveying lead S (seed paper Table 1)


def run_case(case: str, out: Path, *variables: tuple[str, object], expect_ok: bool = True,
             extra: tuple[str, ...] = ()) -> subprocess.CompletedProcess:
    command = [PYTHON, "-m", "tsg_cases.run_case", case, "--scale", "demo", "--out", str(out), *extra]
    for name, value in variables:
        command += ["-v", name, str(value)]
    proc = subprocess.run(command, capture_output=True, text=True, timeout=900)
    if expect_ok:
        assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return proc


def parameters(log: str) -> dict[str, str]:
    line = next(l for l in log.splitlines() if l.startswith("TSG-PARAMETERS"))
    return dict(item.split("=", 1) for item in line.split()[1:])


def conveying_axial_velocity(out: Path) -> float:
    run = Run(out)  # run_case.py copies the run's zones file
    zones, stats = run.zones, run.elements
    mass = stats.column("mass")
    conveying = np.array([k == "conveying" for k in zones.kind])
    weighted = (stats.column("mean_axial_velocity") * mass)[:, conveying].sum()
    return weighted / mass[:, conveying].sum()


@pytest.fixture(scope="module")
def periodic_forward(tmp_path_factory):
    out = tmp_path_factory.mktemp("periodic")
    run_case("periodic", out, ("t_startup", 0.004), ("t_sample", 0.006), ("thermo_every", 500), ("stats_every", 500))
    return out


def test_periodic_conveys_downstream_at_a_plausible_speed(periodic_forward):
    velocity = conveying_axial_velocity(periodic_forward)
    # flights push towards +x; a particle cannot outrun the flight pattern, lead x speed = 0.25 m/s
    assert 0.005 < velocity < LEAD * 600 / 60


def test_periodic_reversed_rotation_conveys_upstream(tmp_path):
    run_case("periodic", tmp_path, ("screw_direction", -1), ("t_startup", 0.004), ("t_sample", 0.006),
             ("thermo_every", 500), ("stats_every", 500))
    assert -LEAD * 600 / 60 < conveying_axial_velocity(tmp_path) < -0.005


def fill_diameters(run_dir: Path) -> np.ndarray:
    """The diameters of the fill's data file (fill.in.data, `Atoms` section of atom_style granular:
    id type diameter density x y z), read here independently of the code that wrote it."""
    lines = (run_dir / "fill.in.data").read_text().splitlines()
    atoms = lines[lines.index("Atoms") + 1:]
    return np.array([float(line.split()[2]) for line in atoms if line.strip()])


def test_periodic_conserves_mass_and_loses_nothing(periodic_forward):
    log = (periodic_forward / "log.lammps").read_text()
    fill = (periodic_forward / "fill.in").read_text()
    count = int(re.search(r"variable fill_count equal (\d+)", fill).group(1))
    for block in parse_thermo(log):
        assert np.all(block["Atoms"] == count)
        assert np.all(block["escaped"] == 0)
    assert f"TSG-DONE escaped 0 particles {count}" in log
    # the element masses tile the periodic domain: their sum is the particle mass at every sample
    diameters = fill_diameters(periodic_forward)
    assert len(diameters) == count
    total = np.sum(1263 * np.pi / 6 * diameters ** 3)
    stats = Run(periodic_forward).elements
    # elements.txt prints 6 significant digits per zone (fix ave/time), so agreement to ~1e-6
    np.testing.assert_allclose(stats.column("mass").sum(axis=1), total, rtol=5e-6)


def test_periodic_outputs_are_present_and_parseable(periodic_forward):
    flow = Run(periodic_forward).massflow
    assert flow.flow.shape[1] == 2 and len(flow.flow) >= 2 and np.all(np.isfinite(flow.flow))
    records = Run(periodic_forward).residence
    assert records.time_by_zone.shape[1] == 8
    stats = Run(periodic_forward).elements
    assert stats.values.shape[1] == 8
    assert np.all((stats.column("solid_fraction") >= 0) & (stats.column("solid_fraction") < 0.74))


def test_fill_density_is_the_runs_rho_p(tmp_path):
    # -v rho_p 1500 reaches the particles: the mass LIGGGHTS measures in the elements equals the
    # fill's diameters at 1500 kg/m^3 (materials.in's 1263 would be 16 % lighter)
    run_case("periodic", tmp_path, ("rho_p", 1500), ("t_startup", 1e-5), ("t_sample", 0.0004),
             ("thermo_every", 50), ("stats_every", 50))
    fill = (tmp_path / "fill.in").read_text()
    diameters = fill_diameters(tmp_path)
    assert len(diameters) == int(re.search(r"fill_count equal (\d+)", fill).group(1))
    total = np.sum(1500 * np.pi / 6 * diameters ** 3)
    stats = Run(tmp_path).elements
    np.testing.assert_allclose(stats.column("mass").sum(axis=1), total, rtol=5e-6)
    params = json.loads((tmp_path / "params.json").read_text())
    assert params["rho_p"] == 1500.0 and params["variables"]["rho_p"] == "1500"
    assert total == pytest.approx(2.3e-3, rel=0.05)    # the fill holds the hold-up mass at that density


def inject_into_run(text: str, phase: int, command: str) -> str:
    """The input with `command` added to the every-commands of its phase-th `run` (0-based; a run
    command may continue over lines ending in &)."""
    lines = text.splitlines()
    starts = [k for k, line in enumerate(lines) if line.startswith("run ")]
    end = starts[phase]
    while lines[end].rstrip().endswith("&"):
        end += 1
    lines[end] += f' "{command}"'
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("case,phase", [("periodic", 0), ("periodic", 1), ("nonperiodic", 0), ("full", 0), ("full", 1)],
                         ids=["periodic-start-up", "periodic-sampling", "nonperiodic", "full-start-up", "full-sampling"])
def test_every_phase_stops_on_a_lost_particle(request, tmp_path, case, phase):
    # the case file itself, with one fault injected into one run phase: after the first thermo
    # chunk particle 1 gets 2 km/s towards +z and leaves the box within the next chunk; the run
    # must stop on the lost atom, not go on with one particle fewer (each thermo_style resets
    # `thermo_modify lost`: cases/include/thermo.in re-arms it for every phase)
    earlier = request.getfixturevalue({"periodic": "periodic_forward", "nonperiodic": "nonperiodic_run",
                                       "full": "full_steady_run"}[case])
    text = (ROOT / "cases" / f"in.tsg_{case}").read_text()
    (tmp_path / "in.faulty").write_text(inject_into_run(text, phase, "set atom 1 vz 2000"))
    variables = json.loads((earlier / "params.json").read_text())["variables"]
    variables["out_dir"] = str(tmp_path)
    # this test is about the lost-atom check: the speed and wall guards (which would stop the 2 km/s
    # particle first) are put out of its way
    variables.update({"guard_max_speed": 1e6, "guard_max_wall_overlap": 1e6})
    if case == "periodic":
        variables.update({"t_startup": 0.003, "t_sample": 0.003})
    proc = subprocess.run(lmp_command("in.faulty", variables), cwd=tmp_path, capture_output=True,
                          encoding="utf-8", errors="replace", env=lmp_environment(), timeout=600)
    log = (tmp_path / "log.lammps").read_text(errors="replace")
    assert proc.returncode != 0, log[-2000:]
    assert "ERROR: Lost atoms" in log and "TSG-DONE" not in log, log[-2000:]
    # it stopped in the phase the fault was put in
    if case == "periodic":   # only the sampling thermo has the sensor columns
        headers = [line for line in log.splitlines() if line.split()[:1] == ["Step"]]
        assert ("massflow" in headers[-1]) == (phase == 1), headers[-1]
    if case == "full":       # the sampling phase follows the steady state
        assert ("TSG-STEADY" in log) == (phase == 1)


@pytest.mark.parametrize("phase", [0, 1], ids=["start-up", "sampling"])
def test_periodic_stops_on_a_particle_lost_between_chunks(periodic_forward, tmp_path, phase):
    # particle 1 put outside the box between two chunks of `run N every M`: LIGGGHTS drops it at the
    # next chunk's set-up; LIGGGHTS' lost-atom count carries across runs (patches/thermo-cpp.patch)
    text = (ROOT / "cases" / "in.tsg_periodic").read_text()
    (tmp_path / "in.faulty").write_text(inject_into_run(text, phase, "set atom 1 z 0.02"))
    variables = json.loads((periodic_forward / "params.json").read_text())["variables"]
    variables.update({"out_dir": str(tmp_path), "t_startup": 0.003, "t_sample": 0.003})
    proc = subprocess.run(lmp_command("in.faulty", variables), cwd=tmp_path, capture_output=True,
                          encoding="utf-8", errors="replace", env=lmp_environment(), timeout=600)
    log = (tmp_path / "log.lammps").read_text(errors="replace")
    count = int(re.search(r"variable fill_count equal (\d+)", (periodic_forward / "fill.in").read_text()).group(1))
    assert proc.returncode != 0 and "TSG-DONE" not in log, log[-2000:]
    assert f"ERROR: Lost atoms: {count} at the previous check" in log and f"{count - 1} now" in log, log[-2000:]


def test_var_changes_the_intended_parameter_only(periodic_forward, tmp_path):
    run_case("periodic", tmp_path, ("mus_pg", 0.3), ("t_startup", 1e-5), ("t_sample", 1e-5))
    reference = parameters((periodic_forward / "log.lammps").read_text())
    variant = parameters((tmp_path / "log.lammps").read_text())
    changed = {k for k in reference if reference[k] != variant[k]} - {"thermo_every", "stats_every"}
    assert changed == {"mus_pg"} and float(variant["mus_pg"]) == 0.3


@pytest.fixture(scope="module")
def nonperiodic_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("nonperiodic")
    run_case("nonperiodic", out, ("t_run", 0.002), ("thermo_every", 500), ("stats_every", 500))
    return out


@pytest.fixture(scope="module")
def full_steady_run(tmp_path_factory):
    # the steady-state branch with a tolerance that any positive outflow meets and both sensors
    # inside the feed zone, so the branch is reached in milliseconds
    out = tmp_path_factory.mktemp("full")
    run_case("full", out, ("sensor_1", 0.004), ("sensor_2", 0.02), ("steady_tolerance", 1e6),
             ("t_max_startup", 0.05), ("stats_every", 200), ("thermo_every", 100), ("t_sample", 0.0004),
             ("inside_records", 1))
    return out


def test_nonperiodic_generates_cohesive_particles_without_losses(nonperiodic_run):
    tmp_path = nonperiodic_run
    log = (tmp_path / "log.lammps").read_text()
    assert parameters(log)["cohesion"] == "1"
    assert "pair_style gran model eepa" in (ROOT / "cases" / "include" / "pair_eepa.in").read_text()
    inserted = int(re.search(r"inserted (\d+) particle templates", log).group(1))
    thermo = parse_thermo(log)[-1]
    assert inserted > 100 and thermo["Atoms"][-1] == inserted
    assert np.all(thermo["escaped"] == 0)
    Run(tmp_path).residence  # parses


@pytest.mark.parametrize("name,value,message,status", [
    ("cohesion", 2, "cohesion = 2 is not allowed", 1),          # refused by LIGGGHTS (models.in)
    ("screw_drive", "spin", "screws_spin.in", 1),                # no such include
    ("psd_sigma", 0.3, "psd_sigma = 0.3 is not allowed", 2),     # refused by the runner, before the feed
])
def test_bad_case_variable_is_a_clear_error(tmp_path, name, value, message, status):
    proc = run_case("nonperiodic", tmp_path, (name, value), ("t_run", 1e-5), expect_ok=False)
    assert proc.returncode == status
    log = tmp_path / "log.lammps"
    assert message in proc.stderr + proc.stdout + (log.read_text(errors="replace") if log.exists() else "")


def test_full_case_feeds_and_stops_clearly_without_steady_state(tmp_path):
    # a start-up limit far too short for steady state: the window loop runs, particles are fed,
    # and the run ends with an error that names the limit and both sensor flows
    proc = run_case("full", tmp_path, ("t_max_startup", 0.0005), ("stats_every", 200), ("thermo_every", 100),
                    expect_ok=False)
    assert proc.returncode == 1
    assert "no steady state by t =" in proc.stderr and "t_max_startup = 0.0005" in proc.stderr
    log = (tmp_path / "log.lammps").read_text(errors="replace")
    assert int(re.search(r"inserted (\d+) particle templates", log).group(1)) > 100
    assert parameters(log)["cohesion"] == "0"
    assert not (tmp_path / "steady.restart").exists()


def test_analysis_report_on_a_real_case_run(periodic_forward, tmp_path):
    # the post-analysis package on the output of our own case run (not a synthetic fixture)
    import json
    proc = subprocess.run([PYTHON, "-m", "tsg_analysis", "report", str(periodic_forward), "--out", str(tmp_path),
                           "--no-snapshot"],
                          capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(ROOT / "analysis")))
    assert proc.returncode == 0, proc.stderr[-2000:]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert (tmp_path / "report.md").is_file()
    missing = {item["part"] for item in summary["not_produced"]}
    # a 10 ms run has too few complete passes for an RTD and no dumps; the element profiles must be there
    assert "element profiles" not in missing and "zones" not in missing, summary["not_produced"]


def test_full_case_steady_branch_writes_restart_and_holdup(full_steady_run):
    # restart, hold-up summary, sampling window with element statistics
    tmp_path = full_steady_run
    log = (tmp_path / "log.lammps").read_text(errors="replace")
    steady = re.search(r"TSG-STEADY t (\S+) holdup (\S+)", log)
    assert steady and float(steady.group(2)) > 0
    assert (tmp_path / "steady.restart").stat().st_size > 0
    mass, count, mfs1, mfs2 = (tmp_path / "holdup.txt").read_text().splitlines()[1].split()
    assert float(mass) == pytest.approx(float(steady.group(2)), rel=1e-6) and int(count) > 0 and float(mfs2) > 0
    run = Run(tmp_path)
    assert run.elements.values.shape[1] == len(run.zones)


def test_full_case_inside_records_account_for_every_particle_once(full_steady_run):
    # inside_records 1: one "inside" record per particle in the machine at the end, none twice, none for
    # a particle that left, all at the end time, although the sampling run ends a run every thermo_every steps
    log = (full_steady_run / "log.lammps").read_text(errors="replace")
    atoms_at_end = int(parse_thermo(log)[-1]["Atoms"][-1])
    records = Run(full_steady_run).residence
    inside = records.exit_reason == "inside"
    assert np.count_nonzero(inside) == atoms_at_end > 0
    assert len(np.unique(records.ids[inside])) == atoms_at_end
    assert not np.isin(records.ids[inside], records.ids[~inside]).any()
    assert np.ptp(records.exit_time[inside]) == 0.0
    # the whole axis is the analysis domain: entry + time inside = the end, and the zones' times add up to it
    np.testing.assert_allclose(records.entry_time[inside] + records.residence_time[inside], records.exit_time[inside],
                               rtol=0, atol=1e-9)
    np.testing.assert_allclose(records.time_by_zone[inside].sum(axis=1), records.residence_time[inside], rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("name", ["report", "element_profiles"])
def test_notebook_executes_on_a_real_case_run(periodic_forward, tmp_path, name):
    import nbformat
    from nbclient import NotebookClient
    notebooks = ROOT / "analysis" / "notebooks"
    notebook = nbformat.read(notebooks / f"{name}.ipynb", as_version=4)
    cell = next(c for c in notebook.cells if "parameters" in c.metadata.get("tags", []))
    cell.source = f"RUN_DIRS = [{str(periodic_forward)!r}]\nOUT_DIR = {str(tmp_path)!r}"
    NotebookClient(notebook, timeout=300, kernel_name="python3",
                   resources={"metadata": {"path": str(notebooks)}}).execute()
    errors = [o for c in notebook.cells if c.cell_type == "code" for o in c.outputs if o.output_type == "error"]
    assert not errors, errors


@pytest.mark.parametrize("gravity", [0.0, 9.81, 19.62])
def test_gravity_variable_accelerates_the_resting_fill_as_free_fall(tmp_path, gravity):
    """-v gravity g: for 0.2 ms after the static fill (screws nearly still; no particle falls far
    enough, 0.2 um, to reach anything it does not touch already) every particle falls freely, so
    the kinetic energy is M (g t)^2 / 2, M the fill's mass from its data file (diameter, density)."""
    run_case("periodic", tmp_path, ("gravity", gravity), ("rpm", 0.001), ("t_startup", 2e-4), ("t_sample", 1e-5),
             ("thermo_every", 20), extra=("--holdup-g", "0.3"))
    log = (tmp_path / "log.lammps").read_text()
    assert float(parameters(log)["gravity"]) == gravity
    data = (tmp_path / "fill.in.data").read_text().split("Atoms")[1].split()
    atoms = np.array(data, dtype=float).reshape(-1, 7)          # id type diameter density x y z
    mass = float(np.sum(atoms[:, 3] * np.pi * atoms[:, 2] ** 3 / 6))
    last = parse_thermo(log)[-1]
    t, energy = float(last["Time"][-1]), float(last["KinEng"][-1])
    assert t > 2e-4
    if gravity == 0.0:
        assert energy == 0.0
    else:
        assert energy == pytest.approx(0.5 * mass * (gravity * t) ** 2, rel=2e-3)


def test_dump_from_starts_the_particle_dumps_there_and_leaves_the_trajectory_alone(tmp_path):
    """-v dump_from S: the first particle dump at step S, then at multiples of dump_every; none before
    (the periodic case dumps in its sampling run, here from step 40). Dumps only write, so the run's
    thermo output equals that of the same run without dumps."""
    common = (("t_startup", 1e-4), ("t_sample", 1e-4), ("thermo_every", 10))
    run_case("periodic", tmp_path / "dumped", *common, ("dump_every", 10), ("dump_from", 55), extra=("--holdup-g", "0.3"))
    run_case("periodic", tmp_path / "plain", *common, extra=("--holdup-g", "0.3"))
    steps = sorted(int(re.search(r"particles_(\d+)\.vtk", p.name).group(1))
                   for p in (tmp_path / "dumped" / "dumps").glob("particles_*.vtk") if "boundingBox" not in p.name)
    last = int(parse_thermo((tmp_path / "dumped" / "log.lammps").read_text())[-1]["Step"][-1])
    assert last > 60
    assert steps == [55] + list(range(60, last + 1, 10))
    dumped, plain = (parse_thermo((tmp_path / name / "log.lammps").read_text()) for name in ("dumped", "plain"))
    assert [list(block["KinEng"]) for block in dumped] == [list(block["KinEng"]) for block in plain]
