"""The cluster job script continues a run from its newest restart file (cases/slurm/segment.sh):
sbatch is a stub that records the successor it is asked to submit; segment 1 is killed after it
wrote restart files (as a job at its time limit), segment 2 continues from the newest complete one
and finishes; its element statistics, merged with segment 1's, equal those of the same run done in
one piece; a third segment finds the run done."""
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tsg_cases.run_case import UserError, read_lmp_vars

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
BUILD = Path(os.environ.get("TSG_BUILD_DIR", ROOT / "build"))
SEGMENT = ROOT / "cases" / "slurm" / "segment.sh"
DATA = ROOT / "tests" / "cases" / "inputs" / "fill40.in.data"
D_MIN = 3.373787550e-04   # m: the smallest diameter of the fill the 40 particles come from (its time step)
DT = 4.9793e-7            # s: 0.1 of the Rayleigh time of D_MIN (the case's time step)


def fill(tmp: Path) -> Path:
    (tmp / "fill40.in.data").write_bytes(DATA.read_bytes())
    (tmp / "fill40.in").write_text(
        "read_data ${fill_file}.data add\nset group all density ${rho_p}\nvariable fill_count equal 40\n"
        f"variable d_min equal {D_MIN!r}\nvariable fill_d_mean equal 0.0004\nvariable fill_psd_sigma equal 0.05\n"
        "variable fill_rho_p equal 1263\nvariable fill_domain_length equal 0.0958333333333\n")
    return tmp / "fill40.in"


def environment(tmp: Path, out: Path, job: int, t_sample: float) -> dict[str, str]:
    stub = tmp / "bin"
    stub.mkdir(exist_ok=True)
    (stub / "sbatch").write_text(f'#!/bin/sh\necho "$@" >> {tmp}/sbatch.log\necho 9{job}\n')
    (stub / "sbatch").chmod(0o755)
    # the d_min of the 40 particles gives this dt: t_startup 100 steps, then t_sample
    variables = (f"-var fill_file {fill(tmp)} -var mesh_dir {BUILD / 'meshes' / 'consigma1-periodic-5um'} "
                 f"-var t_startup {100 * DT!r} -var t_sample {t_sample!r} -var thermo_every 50 -var stats_every 50")
    return dict(os.environ, PATH=f"{stub}:{os.environ['PATH']}", SLURM_JOB_ID=str(job), SLURM_NTASKS="1",
                TSG_OUT=str(out), TSG_LAUNCH="", TSG_RESTART_EVERY="200", TSG_VARS=variables,
                TSG_LMP=os.environ.get("TSG_LMP", str(BUILD / "lmp")))


def segment(env: dict[str, str], **kwargs) -> subprocess.Popen:
    return subprocess.Popen([str(SEGMENT), "periodic", "JOB_SCRIPT"], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, **kwargs)


def thermo_steps(log: Path) -> list[int]:
    return [int(m.group(1)) for m in re.finditer(r"^\s+(\d+)\s+[\d.e+-]+\s+40\s", log.read_text(errors="replace"), re.M)]


def elements(path: Path) -> dict[int, np.ndarray]:
    blocks, step, rows = {}, None, []
    for line in path.read_text().splitlines():
        words = line.split()
        if line.startswith("#") or not words:
            continue
        if len(words) == 2:
            if step is not None:
                blocks[step] = np.array(rows)
            step, rows = int(words[0]), []
        else:
            rows.append([float(w) for w in words[1:]])
    blocks[step] = np.array(rows)
    return blocks


def test_a_killed_segment_is_continued_from_its_restart_file(tmp_path):
    out = tmp_path / "out"
    # segment 1: a long plan, killed (with the job script, as SLURM does) once a restart file is
    # complete, i.e. the log shows a thermo row after it
    first = segment(environment(tmp_path, out, 101, 0.05), start_new_session=True)
    deadline = time.monotonic() + 600
    while time.monotonic() < deadline and first.poll() is None:
        steps = thermo_steps(out / "log.lammps") if (out / "log.lammps").is_file() else []
        if (out / "restart.200").is_file() and steps and steps[-1] > 200:
            break
        time.sleep(0.01)
    assert first.poll() is None, first.stdout.read()
    os.killpg(first.pid, signal.SIGKILL)
    first.wait()
    assert not (out / "DONE").exists()
    reached = thermo_steps(out / "log.lammps")[-1]
    newest = max(int(p.name.split(".")[1]) for p in out.glob("restart.*"))
    # segment 2: the same run with a plan that ends 300 steps after where segment 1 got
    end = 100 * ((reached + 300) // 100)
    t_sample = (end - 100) * DT
    second = segment(environment(tmp_path, out, 102, t_sample))
    log2 = second.communicate(timeout=600)[0]
    assert second.returncode == 0 and (out / "DONE").is_file(), log2
    continued = int(re.search(r"continuing from restart\.(\d+)", log2).group(1))
    assert 200 <= continued < reached and continued <= newest, log2
    steps = thermo_steps(out / "log.lammps")
    assert steps[0] == continued and steps[-1] == end, steps     # it started at the restart's step
    assert "Resetting per-atom state of Fix walls Style wall/gran/corotating from restart" in (out / "log.lammps").read_text()
    assert (out / f"log.upto-{reached}.lammps").is_file() and not list(out.glob("restart.*"))
    submitted = (tmp_path / "sbatch.log").read_text().splitlines()
    assert submitted == ["--parsable --dependency=afterany:101 JOB_SCRIPT", "--parsable --dependency=afterany:102 JOB_SCRIPT"]
    # the same plan in one piece: the merged element statistics agree step by step
    whole = tmp_path / "whole"
    reference = segment(environment(tmp_path, whole, 201, t_sample))
    assert reference.wait(timeout=600) == 0 and (whole / "DONE").is_file()
    merged, single = elements(out / "elements.txt"), elements(whole / "elements.txt")
    assert sorted(merged) == sorted(single) == list(range(100, end + 1, 50)), (sorted(merged), sorted(single))
    for step in single:
        np.testing.assert_allclose(merged[step], single[step], rtol=1e-9, atol=1e-15, err_msg=f"step {step}")
    # a successor that starts after the run is done does nothing
    third = segment(environment(tmp_path, out, 103, t_sample))
    assert third.wait(timeout=60) == 0 and "is done: nothing to run" in third.stdout.read()


def full_variables(tmp: Path, t_sample: float) -> tuple[Path, str]:
    """The full case at demo scale, fed at the inlet, with both sensors in the feed zone and a
    tolerance that any outflow meets (steady in about 6000 steps), windows of 200 steps: a one-piece
    reference run by the runner (which prepares the feed regions and the meshes), and the -var list
    that makes segment.sh run the same input."""
    reference = tmp / "whole-full"
    variables = {"sensor_1": 0.004, "sensor_2": 0.02, "steady_tolerance": 1e6, "t_max_startup": 0.05,
                 "stats_every": 200, "thermo_every": 100, "t_sample": t_sample, "restart_every": 200}
    command = [sys.executable, "-m", "tsg_cases.run_case", "full", "--scale", "demo", "--out", str(reference)]
    for name, value in variables.items():
        command += ["-v", name, str(value)]
    proc = subprocess.run(command, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    used = json.loads((reference / "params.json").read_text())["variables"]
    feed = tmp / "feed.in"
    feed.write_bytes((reference / "feed.in").read_bytes())
    used.update(feed_file=str(feed))
    return reference, " ".join(f"-var {name} {value}" for name, value in used.items()
                               if name not in ("out_dir", "case_dir", "restart_every"))


def kill_after_restart(env: dict[str, str], case: str, out: Path, step: int, command: list[str] | None = None) -> int:
    """Runs one segment (or `command`, which runs one) and kills it (with its job script, as SLURM
    does at the time limit) once restart.<step> is complete and the run has written the next
    mass-flow window after it (the log shows thermo row step + 200); the last step it reached."""
    screen = (out.parent / f"screen-{env['SLURM_JOB_ID']}.txt").open("w")   # a pipe nobody reads would fill and stall lmp
    job = subprocess.Popen(command or [str(SEGMENT), case, "JOB_SCRIPT"], env=env, stdout=screen,
                           stderr=subprocess.STDOUT, text=True, start_new_session=True)
    deadline = time.monotonic() + 600
    reached = 0
    while time.monotonic() < deadline and job.poll() is None:
        log = out / "log.lammps"
        rows = re.findall(r"^\s+(\d+)\s+[\d.e+-]+\s+\d+\s", log.read_text(errors="replace"), re.M) if log.is_file() else []
        reached = int(rows[-1]) if rows else 0
        if (out / f"restart.{step}").is_file() and reached >= step + 200:
            break
        time.sleep(0.01)
    assert job.poll() is None, screen.name
    os.killpg(job.pid, signal.SIGKILL)
    job.wait()
    screen.close()
    return reached


def test_a_full_case_run_killed_in_start_up_and_in_sampling_equals_one_run(tmp_path):
    # the full case continues from restart files in both phases (the window-by-window start-up, then
    # the sampling after the steady state, phase.in); the records the killed segments wrote after
    # their restart files are dropped, so every output equals the run done in one piece
    whole, variables = full_variables(tmp_path, 0.002)
    steady = int(re.search(r"steady_step index (\d+)", (whole / "phase.in").read_text()).group(1))
    out = tmp_path / "segments"
    env = dict(environment(tmp_path, out, 301, 0.0), TSG_VARS=variables)
    in_start_up = kill_after_restart(env, "full", out, 2000)
    assert in_start_up < steady and not (out / "DONE").exists()
    assert "steady_step index -1" in (out / "phase.in").read_text()
    env["SLURM_JOB_ID"] = "302"
    in_sampling = kill_after_restart(env, "full", out, steady + 400)
    assert in_sampling > steady + 400 and not (out / "DONE").exists()
    assert f"steady_step index {steady}" in (out / "phase.in").read_text()
    env["SLURM_JOB_ID"] = "303"
    last = subprocess.run([str(SEGMENT), "full", "JOB_SCRIPT"], env=env, capture_output=True, text=True, timeout=600)
    assert last.returncode == 0 and (out / "DONE").is_file(), last.stdout[-3000:]
    assert f"continuing from restart.{steady + 400}" in last.stdout or f"continuing from restart.{steady + 600}" in last.stdout, last.stdout
    logs = "".join(log.read_text() for log in out.glob("log*.lammps"))
    assert logs.count("dropped") >= 2, logs    # mass-flow rows after the restart, in both continued segments
    for name in ("massflow.txt", "holdup.txt", "residence.txt"):
        assert (out / name).read_text() == (whole / name).read_text(), name
    merged, single = elements(out / "elements.txt"), elements(whole / "elements.txt")
    assert sorted(merged) == sorted(single) and len(single) >= 5
    for step in single:
        np.testing.assert_allclose(merged[step], single[step], rtol=1e-9, atol=1e-15, err_msg=f"step {step}")


def test_the_job_scripts_wall_overlap_reaches_the_guard(tmp_path):
    """TSG_WALL_OVERLAP (documented in the paper-scale job scripts: their machine squeezes its
    particles) becomes the case's guard_max_wall_overlap: a value the guard cannot take is refused
    by name."""
    for script in ("tsg-periodic.slurm", "tsg-full.slurm"):
        assert "TSG_WALL_OVERLAP" in (SEGMENT.parent / script).read_text()
    out = tmp_path / "out"
    env = dict(environment(tmp_path, out, 401, 100 * DT), TSG_WALL_OVERLAP="-0.9")
    proc = segment(env)
    text = proc.communicate(timeout=600)[0] + (out / "log.lammps").read_text(errors="replace")
    assert "guard_max_wall_overlap = -0.9 is not allowed" in text, text[-3000:]
    assert (out / "FAILED").is_file()


def test_a_prepared_run_is_prepared_once_and_continued_with_its_variables(tmp_path):
    """TSG_PREPARE (tsg-periodic-passing.slurm: the paper's particles on a machine whose gaps pass
    them): the first segment prepares the run directory (tsg-run-case --prepare-only: the machine's
    meshes, the fill, lmp.vars) and runs it; killed after a restart file, the next segment continues
    with the same variables without preparing again and finishes; its element statistics merged
    with the first segment's equal the same plan run in one piece; TSG_VARS wins over lmp.vars."""
    assert "TSG_PREPARE" in (SEGMENT.parent / "tsg-periodic-passing.slurm").read_text()
    t_startup = 2.5e-4      # s: about 100 steps of the 1 mm demo

    def env_for(out: Path, job: int, t_sample: float) -> dict[str, str]:
        return dict(environment(tmp_path, out, job, 0.0), TSG_PREPARE="--scale demo --holdup-g 0.05 --seed 3",
                    TSG_VARS=f"-var t_startup {t_startup!r} -var t_sample {t_sample!r} -var thermo_every 50 -var stats_every 50")

    out = tmp_path / "out"
    reached = kill_after_restart(env_for(out, 501, 0.05), "periodic", out, 200)
    first = (tmp_path / "screen-501.txt").read_text()
    assert "preparing: tsg-run-case periodic --scale demo" in first and "variables of" in first, first[-3000:]
    prepared = read_lmp_vars(out)
    assert prepared["mesh_dir"].endswith("consigma1-periodic-4um-c1.4-2.8mm-g1.4mm"), prepared
    assert prepared["t_sample"] == "0.2" and prepared["fill_file"] == str(out / "fill.in")
    count = int(re.search(r"variable fill_count equal (\d+)", (out / "fill.in").read_text()).group(1))
    assert 50 <= count <= 100, count
    fill_written = (out / "fill.in").stat().st_mtime_ns
    rows = re.findall(rf"^\s+(\d+)\s+([\d.e+-]+)\s+{count}\s", (out / "log.lammps").read_text(), re.M)
    dt = float(rows[-1][1]) / int(rows[-1][0])
    end = 100 * ((reached + 300) // 100)
    t_sample = (end - round(t_startup / dt)) * dt
    second = subprocess.run([str(SEGMENT), "periodic", "JOB_SCRIPT"], env=env_for(out, 502, t_sample),
                            capture_output=True, text=True, timeout=600)
    assert second.returncode == 0 and (out / "DONE").is_file(), second.stdout[-3000:]
    assert "preparing" not in second.stdout and "continuing from restart." in second.stdout, second.stdout
    assert (out / "fill.in").stat().st_mtime_ns == fill_written
    steps = [int(m) for m in re.findall(rf"^\s+(\d+)\s+[\d.e+-]+\s+{count}\s", (out / "log.lammps").read_text(), re.M)]
    assert steps[-1] == end, steps     # TSG_VARS' t_sample, not lmp.vars' 0.2 s
    whole = tmp_path / "whole"
    reference = subprocess.run([str(SEGMENT), "periodic", "JOB_SCRIPT"], env=env_for(whole, 601, t_sample),
                               capture_output=True, text=True, timeout=600)
    assert reference.returncode == 0 and (whole / "DONE").is_file(), reference.stdout[-3000:]
    merged, single = elements(out / "elements.txt"), elements(whole / "elements.txt")
    assert sorted(merged) == sorted(single) and len(single) >= 5, (sorted(merged), sorted(single))
    for step in single:
        np.testing.assert_allclose(merged[step], single[step], rtol=1e-9, atol=1e-15, err_msg=f"step {step}")



def thermo_row(step: int) -> str:
    """A thermo row as newest-restart.sh reads it (step, time, then at least eight more columns)."""
    return f"  {step}  {step * DT!r}  40" + "  0" * 8 + "\n"


def test_restart_files_older_than_the_newest_complete_ones_are_removed(tmp_path):
    """prune-restarts.sh keeps the newest KEEP complete restart files (a later thermo row exists) and
    every newer one (being written), removes the older ones and says which; KEEP 0 keeps all."""
    out = tmp_path / "out"
    out.mkdir()
    for step in (200, 400, 600, 800, 1000):
        (out / f"restart.{step}").write_text("x")
    (out / "restart.notes").write_text("not a restart file")
    (out / "log.lammps").write_text("".join(thermo_row(s) for s in range(0, 901, 100)))   # 1000: not complete
    prune = SEGMENT.parent / "prune-restarts.sh"
    kept_all = subprocess.run([str(prune), str(out), "0"], capture_output=True, text=True, timeout=60)
    assert kept_all.returncode == 0 and len(list(out.glob("restart.*"))) == 6, kept_all
    proc = subprocess.run([str(prune), str(out), "2"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in out.glob("restart.*")) == ["restart.1000", "restart.600", "restart.800", "restart.notes"]
    assert sorted(re.findall(r"removed \S+/restart\.(\d+)", proc.stdout)) == ["200", "400"], proc.stdout


def test_a_segment_removes_restart_files_before_and_after_lmp(tmp_path):
    """segment.sh prunes (TSG_KEEP_RESTARTS, default 2) when it continues and when lmp ends before the
    run is done: an lmp stand-in writes two restart files and their thermo rows and stops."""
    out = tmp_path / "out"
    out.mkdir()
    for step in (200, 400, 600):
        (out / f"restart.{step}").write_text("x")
    (out / "log.lammps").write_text("".join(thermo_row(s) for s in range(0, 701, 100)))
    stand_in = tmp_path / "lmp"
    stand_in.write_text("#!/bin/sh\n: > log.lammps\nfor s in 800 1000; do touch restart.$s; "
                        "printf '  %s  0.1  40  0 0 0 0 0 0 0 0\\n' $s $((s + 100)) >> log.lammps; done\n")
    stand_in.chmod(0o755)
    env = dict(environment(tmp_path, out, 701, 100 * DT), TSG_LMP=str(stand_in))
    proc = subprocess.run([str(SEGMENT), "periodic", "JOB_SCRIPT"], env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0 and "continuing from restart.600" in proc.stdout, proc.stdout
    assert sorted(re.findall(r"removed \S+/restart\.(\d+)", proc.stdout), key=int) == ["200", "400", "600"], proc.stdout
    assert sorted(p.name for p in out.glob("restart.*")) == ["restart.1000", "restart.800"]
    assert "successor continues" in proc.stdout and not (out / "FAILED").exists()


def test_lmp_vars_are_read_as_written_and_a_bad_line_is_named(tmp_path):
    """run_case.read_lmp_vars, the one reader of a prepared run's lmp.vars (segment.sh passes the same
    lines to lmp; benchmarks/paper_cost.py times a run with them)."""
    (tmp_path / "lmp.vars").write_text("d_mean 0.0004\nout_dir /a b/c\n")
    assert read_lmp_vars(tmp_path) == {"d_mean": "0.0004", "out_dir": "/a b/c"}
    (tmp_path / "lmp.vars").write_text("d_mean 0.0004\nrpm\n")
    with pytest.raises(UserError, match=r"lmp.vars:2: 'rpm' is not allowed: one 'NAME VALUE' per line"):
        read_lmp_vars(tmp_path)
    with pytest.raises(UserError, match="no such file"):
        read_lmp_vars(tmp_path / "elsewhere")


def test_a_benchmark_prepared_by_an_older_tree_is_named_stale(tmp_path):
    """benchmarks/paper_cost.py times a prepared run's variables; a run it prepared before a scale's
    value changed (the demo's skin_fraction 0.2, which a demo prepared earlier lacks and so ran with the
    case files' 0.4) is stale: prepared again, not timed with the old values."""
    import paper_cost   # benchmarks/ is on PYTHONPATH (tests/CMakeLists.txt)
    prepared = tmp_path / "prepared-demo"
    prepared.mkdir()
    assert paper_cost.stale_variables(prepared, "demo") == ""   # nothing prepared yet
    (prepared / "lmp.vars").write_text("d_mean 0.001\ndt_fraction 0.2\nthermo_every 2000\nstats_every 2000\n"
                                       "out_dir /x\n")
    assert paper_cost.stale_variables(prepared, "demo") == "skin_fraction (none, not 0.2)"
    (prepared / "lmp.vars").write_text("d_mean 0.001\ndt_fraction 0.20\nskin_fraction 0.2\nout_dir /x\n")
    assert paper_cost.stale_variables(prepared, "demo") == ""
    assert paper_cost.stale_variables(prepared, "paper") == "d_mean (0.001, not 0.0004), dt_fraction (0.20, not 0.1)"


def test_a_benchmark_resolves_its_lmp_paths_and_names_a_missing_one(tmp_path, monkeypatch, capsys):
    """paper_cost.py runs lmp from its work directories: a relative --lmp is made absolute before any
    directory change, and a path that is no executable is an error naming the option and the value
    (it was a silent exit 2 from the preparation)."""
    import paper_cost
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as stopped:
        paper_cost.main(["--baseline-lmp", "no/such/lmp", "--lmp", "no/such/lmp"])
    assert stopped.value.code == 2
    message = capsys.readouterr().err
    assert "--lmp no/such/lmp is not allowed: an executable lmp" in message
    assert str(tmp_path / "no" / "such" / "lmp") in message
