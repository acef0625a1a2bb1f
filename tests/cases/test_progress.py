"""Progress lines from a growing LIGGGHTS log (cases/progress.py), and the runner printing them."""
import os
import re
import subprocess
import sys
import textwrap
from io import StringIO
from pathlib import Path

import pytest

from tsg_cases.progress import LogFollower, Progress, duration, follow

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
HEADER = ("    Step           Time    Atoms         KinEng         pp_max       dt_ratio          speed        pg_scr1"
          "        pg_scr2         pg_bar        escaped            CPU \n")


def row(step: int, time: float, atoms: int = 3453, escaped: int = 0, pp: float = 0.01, pg: float = 0.02) -> str:
    return f"{step:8d} {time:14.8g} {atoms:8d} 1e-05 {pp:g} 0.2 1.0 {pg:g} {pg:g} {pg:g} {escaped:d} 12.5\n"


def test_follower_reads_only_complete_lines_as_the_log_grows(tmp_path):
    log = tmp_path / "log.lammps"
    follower = LogFollower(log)
    assert not follower.poll() and follower.latest is None          # no log yet
    log.write_text("LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0)\nTSG-OUTPUT here\n" + HEADER + row(0, 0.0))
    assert follower.poll() and follower.latest["Step"] == 0
    assert follower.events == ["TSG-OUTPUT here"]
    line = row(2000, 0.005, atoms=3450, escaped=2)
    with open(log, "a") as handle:                                   # half a row: not read yet
        handle.write(line[:20])
    assert not follower.poll() and follower.latest["Step"] == 0
    with open(log, "a") as handle:
        handle.write(line[20:] + "WARNING: something (x.cpp:1)\nLoop time of 9 on 2 procs for 2000 steps\n")
    assert follower.poll()
    assert follower.latest["Step"] == 2000 and follower.latest["Atoms"] == 3450 and follower.latest["escaped"] == 2
    # a row after "Loop time" without a new header is not thermo (LIGGGHTS prints statistics there)
    with open(log, "a") as handle:
        handle.write("Pair  | 1 2 3 4 5 6 7 8 9 10 11 12\n")
    assert not follower.poll() and follower.latest["Step"] == 2000
    log.write_text(HEADER + row(10, 1e-5))                          # the log started again (`log` command)
    assert follower.poll() and follower.latest["Step"] == 10


def test_percent_and_eta_against_the_closed_form():
    progress = Progress(total_time=0.1)
    progress.observe({"Time": 0.0}, wall=100.0)
    assert progress.eta(wall=105.0) is None                          # one row: no rate yet
    progress.observe({"Time": 0.02}, wall=140.0)                     # 0.02 s simulated in 40 s: 5e-4 s/s
    assert progress.rate() == pytest.approx(5e-4)
    # 0.08 s left at 5e-4 s/s = 160 s after the row; 10 s of it have passed since
    assert progress.eta(wall=150.0) == pytest.approx(150.0)
    line = progress.line({"Step": 4000, "Time": 0.02, "Atoms": 3453, "escaped": 1, "fast": 3, "pp_max": 0.125,
                          "pg_scr1": 0.25, "pg_scr2": 0.5, "pg_bar": 0.75}, wall=150.0, started=90.0)
    assert "t = 0.02 of 0.1 s (20.0 %)" in line and "ETA 2 min 30 s" in line and "step 4000" in line
    assert "3453 particles" in line and "escaped 1" in line and "fast events 3" in line
    assert "overlap/R pair 0.125, walls 0.25/0.5/0.75" in line and "row 10 s old" in line
    assert Progress(None).line(None, wall=30.0, started=0.0).endswith("setting up (meshes, particles): 30 s since the start")


def test_duration_units():
    assert [duration(s) for s in (4.4, 61, 3725, 3 * 86400)] == ["4 s", "1 min 01 s", "1 h 02 min", "3.0 days"]


WRITER = textwrap.dedent("""
    import sys, time
    log = sys.argv[1]
    header = {header!r}
    with open(log, "w") as f:
        f.write("LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0)\\n"); f.flush()
        time.sleep(0.6)
        f.write(header); f.flush()
        for k in range(9):
            f.write(f"{{1000 * k:8d}} {{0.001 * k:14.8g}} 3453 1e-05 0.01 0.2 1.0 0.02 0.02 0.02 0 1.0\\n"); f.flush()
            time.sleep(0.3)
        f.write("Loop time of 3 on 1 procs for 8000 steps with 3453 atoms\\nTSG-DONE escaped 0 particles 3453\\n")
""")


def test_follow_prints_lines_while_a_process_writes_its_log(tmp_path):
    log = tmp_path / "log.lammps"
    out = StringIO()
    writer = WRITER.format(header=HEADER)
    with subprocess.Popen([sys.executable, "-c", writer, str(log)]) as proc:
        status = follow(proc, log, total_time=0.008, every=0.4, out=out, poll_interval=0.05)
    lines = out.getvalue().splitlines()
    assert status == 0
    assert len(lines) >= 5, lines                    # ~3.3 s of writing, a line every 0.4 s
    assert "setting up" in lines[0]                  # before the first row
    percents = [float(m.group(1)) for m in (re.search(r"\(([\d.]+) %\)", line) for line in lines) if m]
    assert percents == sorted(percents) and percents[-1] == 100.0, lines
    assert "ETA" in lines[-2] and "3453 particles" in lines[-1] and lines[-1].endswith("[lmp exited: 0]")


def test_the_runner_prints_progress_lines(tmp_path):
    # the demo case with a small hold-up, 640 steps with a thermo row every 100; a progress line every second
    env = dict(os.environ, TSG_PROGRESS_EVERY="1")
    proc = subprocess.run([sys.executable, "-m", "tsg_cases.run_case", "periodic", "--scale", "demo", "--out", str(tmp_path),
                           "--holdup-g", "0.3",
                           "-v", "t_startup", "0.0008", "-v", "t_sample", "0.0008", "-v", "thermo_every", "100",
                           "-v", "stats_every", "100"], capture_output=True, text=True, env=env, timeout=900)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    lines = [line for line in proc.stdout.splitlines() if line.startswith("[progress]")]
    assert len(lines) >= 2, proc.stdout
    final = lines[-1]
    # 2 x round(0.0008 s / dt) steps: within one step of the planned 0.0016 s
    assert float(re.search(r"\(([\d.]+) %\)", final).group(1)) > 99.5 and "of 0.0016 s" in final, final
    assert "particles" in final and "escaped 0" in final, final
    assert "overlap/R pair" in final and final.endswith("[lmp exited: 0]")
    assert any(line.startswith("[prepare]") for line in proc.stdout.splitlines()), proc.stdout   # the fill's heartbeat
    assert (tmp_path / "log.lammps").is_file()       # the full log stays in the run directory


def test_follow_command_reads_a_log_to_its_end(tmp_path):
    (tmp_path / "log.lammps").write_text(HEADER + row(0, 0.0) + row(8000, 0.008) + "TSG-DONE escaped 0 particles 3453\n")
    done = subprocess.run([sys.executable, "-m", "tsg_cases.progress", "follow", str(tmp_path), "--total-time", "0.008",
                           "--every", "0.1"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and "t = 0.008 of 0.008 s (100.0 %)" in done.stdout, done.stdout + done.stderr
    assert done.stdout.splitlines()[-1] == "[progress] TSG-DONE escaped 0 particles 3453"
    missing = subprocess.run([sys.executable, "-m", "tsg_cases.progress", "follow", str(tmp_path / "nothing")],
                             capture_output=True, text=True, timeout=60)
    assert missing.returncode == 2 and "does not exist" in missing.stderr


def test_wait_command_beats_while_a_step_works_and_passes_its_status():
    beats = subprocess.run([sys.executable, "-m", "tsg_cases.progress", "wait", "--every", "0.2", "meshes", "--",
                            sys.executable, "-c", "import time; time.sleep(1.1)"], capture_output=True, text=True, timeout=60)
    lines = beats.stdout.splitlines()
    assert beats.returncode == 0 and lines[0] == "[prepare] meshes ..." and lines[-1].startswith("[prepare] meshes: done in")
    assert sum("so far" in line for line in lines) >= 3, lines          # about 5 beats in 1.1 s
    failing = subprocess.run([sys.executable, "-m", "tsg_cases.progress", "wait", "fill", "--", "false"],
                             capture_output=True, text=True, timeout=60)
    assert failing.returncode == 1
