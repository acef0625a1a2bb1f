"""Our C++ compiles without a warning under -Wall -Wextra (the overlay .cpp files, each overlay header
on its own, and the EEPA contact model inside upstream's contact_models.h).

The check targets are outside the default build (CMakeLists.txt, "Warning checks"); their objects are
removed first so that every file is compiled again (ccache replays a cached compile's warnings)."""
import os
import re
import shutil
import subprocess
from pathlib import Path

BUILD = Path(os.environ["TSG_BUILD_DIR"])
OUR_FILE_WARNING = re.compile(r"src-liggghts-eepa/\S+:\d+:\d+: warning:")


def rebuild(target: str) -> subprocess.CompletedProcess:
    for obj in (BUILD / "CMakeFiles" / f"{target}.dir").rglob("*.o"):
        obj.unlink()
    return subprocess.run([shutil.which("cmake"), "--build", str(BUILD), "--target", target, "-j2"],
                          capture_output=True, text=True, timeout=900)


def test_overlay_sources_and_headers_compile_with_werror():
    proc = rebuild("tsg_overlay_werror")
    assert proc.returncode == 0, proc.stdout[-6000:] + proc.stderr[-6000:]
    assert "warning:" not in proc.stdout + proc.stderr


def test_contact_model_has_no_warning_of_ours():
    proc = rebuild("tsg_contact_model_warnings")
    assert proc.returncode == 0, proc.stdout[-6000:] + proc.stderr[-6000:]
    ours = [line for line in (proc.stdout + proc.stderr).splitlines() if OUR_FILE_WARNING.search(line)]
    assert not ours, "\n".join(ours)
