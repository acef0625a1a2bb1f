"""A study run longer than a session (scripts/kept-run.sh; docs/validation.md, "Periodic against full
at 1 mm") is kept in the repository as its newest complete restart file and its outputs, and
continued from them on a fresh checkout: the continued run equals the same run done in one piece. A
finished run is kept as its outputs only."""
import re
import subprocess
from pathlib import Path

import numpy as np
from test_slurm import ROOT, elements, environment, kill_after_restart


def mesh_dir_name(run_dir: Path) -> str:
    """The meshes a run was made on, as its log names them."""
    found = re.search(r"mesh_dir=\S*/([^/\s]+)", (run_dir / "log.lammps").read_text(errors="replace"))
    assert found, f"{run_dir}/log.lammps names no mesh_dir"
    return found.group(1)


def thermo_steps(log: Path) -> list[int]:
    return [int(m) for m in re.findall(r"^\s+(\d+)\s+[\d.e+-]+\s+\d+\s", log.read_text(errors="replace"), re.M)]


def test_a_kept_run_continues_on_a_fresh_checkout_from_its_kept_restart_file(tmp_path):
    """scripts/kept-run.sh (the 1 mm full run of docs/validation.md, longer than a session): a run
    stopped after a restart file is kept (its newest restart file and outputs, compressed); its run
    folder removed, as on a fresh checkout, `run` prepares it again, continues from the kept restart
    file and finishes, and its element statistics equal the same run done in one piece."""
    kept_run = ROOT / "scripts" / "kept-run.sh"
    prepare = ("--scale demo --holdup-g 0.05 --seed 3 -v t_startup 2.5e-4 -v t_sample 2e-3 "
               "-v thermo_every 50 -v stats_every 50")

    def conf(kept: Path, out: Path) -> Path:
        kept.mkdir()
        (kept / "run.conf").write_text(f'CASE=periodic\nOUT={out}\nPREPARE="{prepare}"\nRESTART_EVERY=200\n')
        return kept

    env = {k: v for k, v in environment(tmp_path, tmp_path / "unused", 701, 0.0).items()
           if k not in ("SLURM_JOB_ID", "TSG_VARS", "TSG_OUT", "TSG_LAUNCH", "TSG_RESTART_EVERY")}
    out, kept = tmp_path / "out", conf(tmp_path / "kept", tmp_path / "out")
    kill_after_restart(dict(env, SLURM_JOB_ID="701"), "periodic", out, 200, [str(kept_run), "run", str(kept), "1"])
    keep = subprocess.run([str(kept_run), "keep", str(kept)], env=env, capture_output=True, text=True, timeout=120)
    assert keep.returncode == 0, keep.stdout + keep.stderr
    # the newest complete restart file: one the log shows a later thermo row for
    kept_restarts = [int(p.name.split(".")[1]) for p in kept.glob("restart.*.xz")]
    assert len(kept_restarts) == 1 and (kept / "log.lammps.xz").is_file(), sorted(kept.iterdir())
    newest = kept_restarts[0]
    assert newest >= 200 and newest < thermo_steps(out / "log.lammps")[-1]
    subprocess.run(["rm", "-rf", str(out)], check=True)
    again = subprocess.run([str(kept_run), "run", str(kept), "1"], env=env, capture_output=True, text=True, timeout=600)
    assert again.returncode == 0 and (out / "DONE").is_file(), again.stdout[-3000:] + again.stderr
    assert "preparing" in again.stdout and f"continuing from restart.{newest}" in again.stdout, again.stdout[-3000:]
    # finished, it is kept as its outputs only; on a fresh checkout `run` unpacks them and runs nothing
    done_keep = subprocess.run([str(kept_run), "keep", str(kept)], env=env, capture_output=True, text=True, timeout=120)
    assert done_keep.returncode == 0 and (kept / "DONE").is_file(), done_keep.stdout + done_keep.stderr
    assert not list(kept.glob("restart.*")) and (kept / "elements.txt.xz").is_file(), sorted(kept.iterdir())
    finished = (out / "elements.txt").read_text()
    subprocess.run(["rm", "-rf", str(out)], check=True)
    unpack = subprocess.run([str(kept_run), "run", str(kept), "1"], env=env, capture_output=True, text=True, timeout=120)
    assert unpack.returncode == 0 and "finished run" in unpack.stdout, unpack.stdout + unpack.stderr
    assert (out / "elements.txt").read_text() == finished and not (out / "log.liggghts").exists()
    # what the analysis of a finished run reads besides its outputs: zones and parameters, unpacked; a run
    # kept before they were kept gets them from its preparation
    assert (out / "zones.txt").is_file() and (out / "params.json").is_file(), sorted(p.name for p in out.iterdir())
    for name in ("zones.txt.xz", "params.json.xz"):
        (kept / name).unlink()
    subprocess.run(["rm", "-rf", str(out)], check=True)
    older = subprocess.run([str(kept_run), "run", str(kept), "1"], env=env, capture_output=True, text=True, timeout=600)
    assert older.returncode == 0 and "finished run" in older.stdout, older.stdout + older.stderr
    assert (out / "elements.txt").read_text() == finished and not (out / "log.liggghts").exists()
    assert (out / "zones.txt").read_text() == (ROOT / "build" / "meshes" / mesh_dir_name(out) / "zones.txt").read_text()
    assert '"case": "periodic"' in (out / "params.json").read_text()
    whole_out = tmp_path / "whole"
    whole = subprocess.run([str(kept_run), "run", str(conf(tmp_path / "kept-whole", whole_out)), "1"], env=env,
                           capture_output=True, text=True, timeout=600)
    assert whole.returncode == 0 and (whole_out / "DONE").is_file(), whole.stdout[-3000:]
    merged, single = elements(out / "elements.txt"), elements(whole_out / "elements.txt")
    assert sorted(merged) == sorted(single) and len(single) >= 5, (sorted(merged), sorted(single))
    for step in single:
        np.testing.assert_allclose(merged[step], single[step], rtol=1e-9, atol=1e-15, err_msg=f"step {step}")
