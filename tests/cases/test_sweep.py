"""The sweep driver writes the seed's sensitivity matrix as run directories, runs them resumably and
reports their state."""
import json
import os
import socket
import subprocess
import sys
from pathlib import Path

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SWEEP = [sys.executable, "-m", "tsg_cases.sweep"]


def test_matrix_holds_table_4_and_the_size_series(tmp_path):
    subprocess.run(SWEEP + ["write", str(tmp_path), "--scale", "demo", "--np", "2"], check=True, capture_output=True)
    names = (tmp_path / "runs.txt").read_text().split()
    params = {n: json.loads((tmp_path / n / "sweep.json").read_text())["vars"] for n in names}
    assert params["reference"] == {}
    # Table 4: each variation changes one property, for particle-particle and particle-geometry
    assert params["restitution-0.1"] == {"e_pp": "0.1", "e_pg": "0.1"}
    assert params["restitution-0.9"] == {"e_pp": "0.9", "e_pg": "0.9"}
    assert params["static-friction-0.1"] == {"mus_pp": "0.1", "mus_pg": "0.1"}
    assert params["rolling-friction-0.2"] == {"mur_pp": "0.2", "mur_pg": "0.2"}
    assert params["psd-sigma-0.2"] == {"psd_sigma": "0.2"}
    assert params["cohesion-high"] == {"cohesion": "1"}
    sizes = sorted(float(p["d_mean"]) for n, p in params.items() if n.startswith("diameter"))
    assert sizes[0] == 200e-6 and sizes[-1] == 1500e-6 and len(sizes) == 5
    slurm = (tmp_path / "sweep.slurm").read_text()
    assert f"#SBATCH --array=0-{len(names) - 1}" in slurm and "#SBATCH --ntasks=2" in slurm
    for name in names:
        assert os.access(tmp_path / name / "run.sh", os.X_OK)


def test_run_is_resumable_and_status_reports_states(tmp_path):
    subprocess.run(SWEEP + ["write", str(tmp_path), "--scale", "demo", "--np", "1",
                            "-v", "t_startup", "1e-5", "-v", "t_sample", "1e-5"], check=True, capture_output=True)
    (tmp_path / "restitution-0.9" / "FAILED").write_text("1\n")
    (tmp_path / "psd-sigma-0.2" / "RUNNING").write_text("999999999\n")     # a process that is gone
    # alive here (this test's own process), and on a cluster node that this host cannot check
    (tmp_path / "restitution-0.1" / "RUNNING").write_text(f"{os.getpid()} {socket.gethostname()} \n")
    (tmp_path / "cohesion-high" / "RUNNING").write_text("4242 node17 8811\n")
    busy = subprocess.run(SWEEP + ["run", str(tmp_path), "--only", "restitution-0.1", "cohesion-high"],
                          capture_output=True, text=True)
    assert busy.returncode == 0, busy.stdout + busy.stderr
    assert "restitution-0.1: running, skipped" in busy.stdout
    assert ("cohesion-high: running on node17 (job 8811): not checked from this host, skipped (if no job runs it "
            f"any more, delete {tmp_path / 'cohesion-high' / 'RUNNING'})") in busy.stdout
    assert not (tmp_path / "restitution-0.1" / "log.lammps").exists()
    first = subprocess.run(SWEEP + ["run", str(tmp_path), "--only", "reference"], capture_output=True, text=True)
    assert first.returncode == 0, first.stdout + first.stderr
    assert (tmp_path / "reference" / "DONE").exists() and (tmp_path / "reference" / "log.lammps").exists()
    again = subprocess.run(SWEEP + ["run", str(tmp_path), "--only", "reference"], capture_output=True, text=True)
    assert "reference: done, skipped" in again.stdout
    status = subprocess.run(SWEEP + ["status", str(tmp_path)], capture_output=True, text=True, check=True).stdout
    assert "done 1  running 2  failed 1  pending 7  interrupted 1" in status
    bad = subprocess.run(SWEEP + ["run", str(tmp_path), "--only", "nonsense"], capture_output=True, text=True)
    assert bad.returncode == 2 and "no run named nonsense" in bad.stderr


def test_write_adds_seeds_to_a_sweep_and_refuses_to_rewrite_a_run_with_other_settings(tmp_path):
    common = ["--scale", "demo", "--np", "1", "-v", "t_sample", "0.5"]
    subprocess.run(SWEEP + ["write", str(tmp_path), *common, "--replicas", "3", "--only", "reference", "psd-sigma-0.2"],
                   check=True, capture_output=True)
    (tmp_path / "psd-sigma-0.2" / "seed-1" / "DONE").write_text("")
    subprocess.run(SWEEP + ["write", str(tmp_path), *common, "--seeds", "4", "5", "--only", "psd-sigma-0.2"],
                   check=True, capture_output=True)
    names = (tmp_path / "runs.txt").read_text().split()
    assert names == [f"{setting}/seed-{k}" for setting in ("reference", "psd-sigma-0.2") for k in (1, 2, 3)] + \
        ["psd-sigma-0.2/seed-4", "psd-sigma-0.2/seed-5"]
    assert json.loads((tmp_path / "psd-sigma-0.2" / "seed-5" / "sweep.json").read_text())["seed"] == 5
    assert "--seed 5 periodic" in (tmp_path / "psd-sigma-0.2" / "seed-5" / "run.sh").read_text()
    assert "#SBATCH --array=0-7" in (tmp_path / "sweep.slurm").read_text()
    assert (tmp_path / "psd-sigma-0.2" / "seed-1" / "DONE").exists()          # an existing run keeps its state
    other = subprocess.run(SWEEP + ["write", str(tmp_path), "--scale", "demo", "--np", "1", "-v", "t_sample", "0.9",
                                    "--seeds", "1", "--only", "reference"], capture_output=True, text=True)
    assert other.returncode == 2 and "reference/seed-1 was written with" in other.stderr
    assert '"t_sample": "0.5"' in (tmp_path / "reference" / "seed-1" / "sweep.json").read_text()
    unseeded = subprocess.run(SWEEP + ["write", str(tmp_path), *common, "--only", "reference"], capture_output=True, text=True)
    assert unseeded.returncode == 2 and "already holds reference with fill seeds" in unseeded.stderr
    assert (tmp_path / "runs.txt").read_text().split() == names


def test_a_paper_scale_run_is_a_chain_of_segments(tmp_path):
    """A paper-scale run (9-16 core-hours per simulated second) runs as cases/slurm/segment.sh
    segments: prepared once with the sweep's options, continued from its restart files, and on a
    cluster each array task submits the next job of its own index. Stand-ins for tsg-run-case, lmp
    and sbatch: the first segment ends before the run does, the second finishes it."""
    sweep = tmp_path / "sweep"
    subprocess.run(SWEEP + ["write", str(sweep), "--scale", "paper", "--np", "1", "--only", "reference",
                            "static-friction-0.1"], check=True, capture_output=True)
    run_dir = sweep / "static-friction-0.1"
    prepare = tmp_path / "run_case"
    prepare.write_text('#!/bin/sh\necho "$@" > "$TSG_OUT/prepared-args"\necho "t_sample 1.0" > "$TSG_OUT/lmp.vars"\n')
    lmp = tmp_path / "lmp"   # the first segment stops at step 100, the second writes TSG-DONE
    lmp.write_text("#!/bin/sh\nif [ -f ../ran-once ]; then echo TSG-DONE > log.lammps; "
                   "else touch ../ran-once; echo '  100 0.1 40 0 0 0 0 0 0 0 0' > log.lammps; fi\n")
    stub = tmp_path / "sbatch"
    stub.write_text(f'#!/bin/sh\necho "$@" >> {tmp_path}/sbatch.log\necho 77\n')
    for script in (prepare, lmp, stub):
        script.chmod(0o755)
    env = dict(os.environ, TSG_RUN_CASE=str(prepare), TSG_LMP=str(lmp), TSG_SBATCH=str(stub), TSG_LAUNCH="",
               SLURM_JOB_ID="76", SLURM_ARRAY_TASK_ID="1", TSG_JOB_SCRIPT=str(sweep / "sweep.slurm"))
    first = subprocess.run([str(run_dir / "run.sh")], env=env, capture_output=True, text=True, timeout=120)
    assert first.returncode == 0 and "segment ended before the run did" in first.stdout, first.stdout
    assert (run_dir / "prepared-args").read_text().split() == ["periodic", "--scale", "paper", "-v", "mus_pp", "0.1",
                                                               "-v", "mus_pg", "0.1", "--out", str(run_dir),
                                                               "--prepare-only"]
    assert (tmp_path / "sbatch.log").read_text().split() == [
        "--parsable", "--array=1", "--dependency=afterany:76", str(sweep / "sweep.slurm")]
    assert not (run_dir / "DONE").exists() and not (run_dir / "RUNNING").exists()
    local = subprocess.run(SWEEP + ["run", str(sweep), "--only", "static-friction-0.1"], capture_output=True, text=True,
                           env={k: v for k, v in env.items() if not k.startswith("SLURM")}, timeout=120)
    assert local.returncode == 0 and "static-friction-0.1: done" in local.stdout, local.stdout + local.stderr
    assert (run_dir / "run.out").read_text().count("preparing: tsg-run-case periodic --scale paper") == 1   # once
    assert (run_dir / "DONE").exists()
    assert f'sweep="${{TSG_SWEEP:-{sweep.resolve()}}}"' in (sweep / "sweep.slurm").read_text()
