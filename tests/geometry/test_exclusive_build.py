"""Runs started together (ctest in parallel, a sweep array on a cluster) share build/meshes: a mesh
directory must be built once, and no run may read it half-written (a parallel ctest once failed
with a .part file renamed away under another builder). tsg_meshes.build.exclusive_build is the lock
the runners take around "check, then build"."""
import subprocess
import sys
import textwrap

BUILDER = textwrap.dedent("""
    import sys, time
    from pathlib import Path
    from tsg_meshes.build import exclusive_build
    out = Path(sys.argv[1])
    with exclusive_build(out):
        if not (out / "done").is_file():
            out.mkdir(exist_ok=True)
            with open(out.parent / "builds.log", "a") as log:
                log.write("built\\n")
            (out / "done.part").write_text("x")
            time.sleep(0.5)                      # long enough for the others to arrive meanwhile
            (out / "done.part").rename(out / "done")
        print((out / "done").read_text())
""")


def test_runs_started_together_build_a_directory_once_and_all_see_it_complete(tmp_path):
    out = tmp_path / "meshes" / "shared"
    procs = [subprocess.Popen([sys.executable, "-c", BUILDER, str(out)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(4)]
    results = [p.communicate(timeout=60) for p in procs]
    assert all(p.returncode == 0 for p in procs), results
    assert [stdout.strip() for stdout, _ in results] == ["x"] * 4
    assert (tmp_path / "meshes" / "builds.log").read_text() == "built\n"
