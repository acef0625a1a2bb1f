"""Bad set-up input gets one clear message naming the failing step and what to do."""
import os
import shutil
import subprocess
from pathlib import Path

SOURCE = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def test_wrong_liggghts_source_dir_is_named(tmp_path):
    proc = subprocess.run([shutil.which("cmake"), "-S", str(SOURCE), "-B", str(tmp_path / "b"),
                           f"-DLIGGGHTS_SOURCE_DIR={tmp_path / 'nowhere'}"], capture_output=True, text=True)
    assert proc.returncode != 0
    message = " ".join(proc.stderr.split())
    assert f"LIGGGHTS_SOURCE_DIR='{tmp_path / 'nowhere'}' is not a LIGGGHTS-PUBLIC tree" in message


def test_corrupt_cached_tarball_without_network(tmp_path):
    # a damaged tarball in the cache is detected by its SHA-256 and fetched again; with the network
    # unreachable (a proxy nobody listens on) the script stops with the step and what to do
    (tmp_path / "liggghts_3.8.0+repack1.orig.tar.xz").write_bytes(b"not the upstream tarball")
    env = dict(os.environ, TSG_CACHE_DIR=str(tmp_path), http_proxy="http://127.0.0.1:9", https_proxy="http://127.0.0.1:9")
    proc = subprocess.run([str(SOURCE / "scripts" / "fetch-liggghts.sh")], capture_output=True, text=True,
                          env=env, timeout=300)
    assert proc.returncode == 1
    assert "fails its SHA-256 check" in proc.stderr
    assert "ERROR:" in proc.stderr and "Re-run" in proc.stderr
    assert not (tmp_path / "liggghts_3.8.0+repack1.orig.tar.xz").exists()
