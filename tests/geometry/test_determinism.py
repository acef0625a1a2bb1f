"""The same spec and tolerance give byte-identical files, build after build."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from tsg_meshes.build import MESH_FILES


@pytest.mark.parametrize("config, tolerance", [("consigma1-periodic", "5e-6"), ("consigma1-nonperiodic", "2e-5")])
def test_two_builds_are_byte_identical(tmp_path, config, tolerance):
    outputs = []
    for run, hash_seed in enumerate(("1", "2")):
        outdir = tmp_path / f"build{run}"
        subprocess.run([sys.executable, "-m", "tsg_meshes", "build", config, str(outdir), "--tolerance", tolerance],
                       check=True, capture_output=True, env=dict(os.environ, PYTHONHASHSEED=hash_seed))
        outputs.append({name: (outdir / name).read_bytes() for name in (*MESH_FILES, "zones.txt")})
    for name in outputs[0]:
        assert outputs[0][name] == outputs[1][name], name
        assert len(outputs[0][name]) > 0, name
