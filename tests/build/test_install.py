"""`cmake --install` puts lmp and the extension's docs under a prefix, and the installed lmp works."""
import os
import shutil
import subprocess
from pathlib import Path

BUILD = Path(os.environ.get("TSG_BUILD_DIR", Path(__file__).resolve().parents[2] / "build"))
SOURCE = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def test_install_to_prefix(tmp_path):
    cmake = shutil.which("cmake")
    assert cmake
    subprocess.run([cmake, "--install", str(BUILD), "--prefix", str(tmp_path)], check=True,
                   capture_output=True, text=True)
    lmp = tmp_path / "bin" / "lmp"
    assert lmp.is_file() and os.access(lmp, os.X_OK)
    docs = tmp_path / "share" / "doc" / "tsg-dem"
    assert (docs / "README.md").is_file()
    for doc in (SOURCE / "docs").glob("*.md"):
        assert (docs / doc.name).read_text() == doc.read_text()
    # the installed binary runs and knows our styles
    text = subprocess.run([str(lmp), "-h"], capture_output=True, text=True, cwd=tmp_path).stdout
    assert "eepa" in text and "check/contact" in text
