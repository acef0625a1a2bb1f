"""Shared builds for the geometry tests (built once per pytest process, in memory)."""
from __future__ import annotations

from functools import lru_cache

import pytest

from tsg_meshes.build import BuiltGeometry, DEFAULT_TOLERANCE, generate, resolve_config
from tsg_meshes.spec import read_spec

SHIPPED = ("consigma1-full", "consigma1-periodic", "consigma1-nonperiodic")


@lru_cache(maxsize=None)
def built(name: str, tolerance: float = DEFAULT_TOLERANCE) -> BuiltGeometry:
    return generate(read_spec(resolve_config(name)), tolerance)


@pytest.fixture(scope="session")
def build():
    return built
