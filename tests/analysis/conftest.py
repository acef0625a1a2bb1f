"""Synthetic run directories shared by the analysis tests (written once per test file)."""
import pytest

from make_fixture import write_run


@pytest.fixture(scope="session")
def periodic_run(tmp_path_factory):
    path = tmp_path_factory.mktemp("runs") / "periodic"
    return path, write_run(path, kind="periodic", dumps="txt", seed=1)


@pytest.fixture(scope="session")
def full_run(tmp_path_factory):
    path = tmp_path_factory.mktemp("runs") / "full"
    return path, write_run(path, kind="full", dumps="vtk", seed=2)


@pytest.fixture(scope="session")
def unsteady_run(tmp_path_factory):
    path = tmp_path_factory.mktemp("runs") / "unsteady"
    return path, write_run(path, kind="periodic", steady=False, dumps=None, meshes=False, seed=3)
