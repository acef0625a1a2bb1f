"""Our C++ follows .clang-format: `clang-format --dry-run --Werror` over every C++ file of
src-liggghts-eepa/ and tests/unit/ fails on the first file that would change."""
import os
import shutil
import subprocess
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def our_cxx_files() -> list[Path]:
    return [p for folder in ("src-liggghts-eepa", "tests/unit") for p in sorted((SOURCE / folder).rglob("*"))
            if p.suffix in {".h", ".cpp"}]


def test_files_are_found():
    names = {p.relative_to(SOURCE).as_posix() for p in our_cxx_files()}
    assert "src-liggghts-eepa/contact/normal_model_eepa.h" in names
    assert "src-liggghts-eepa/physics/eepa_law.h" in names
    assert "tests/unit/test_eepa_law.cpp" in names


def test_clang_format_finds_nothing():
    clang_format = shutil.which("clang-format")
    if clang_format is None:
        pytest.fail("clang-format is not installed (apt-get install clang-format)")
    proc = subprocess.run([clang_format, "--dry-run", "--Werror", f"--style=file:{SOURCE / '.clang-format'}",
                           *map(str, our_cxx_files())], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-8000:]
