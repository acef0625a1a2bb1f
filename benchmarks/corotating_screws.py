"""Cost of turning the screws: stock `fix move/mesh rotate` + `fix wall/gran` against
`fix wall/gran/corotating`, measured side by side in one invocation.

    .venv/bin/python benchmarks/corotating_screws.py [--particles 3453] [--np 1] [--skip-case]

1. Screw contact handling per step at about 10k, 50k and 200k triangles per screw (the periodic
   ConsiGma-1 screws meshed at 20, 5 and 1 µm): the demo-scale particle count on prescribed paths
   in the two bores (tests/cases/inputs/in.corotating_paths), run without screws, with the stock
   path and with the corotating fix; the screw cost is the step time minus the step time without
   screws.
2. The whole step of the periodic demo case (cases/run_case.py periodic --scale demo) with either
   drive over the same short run.
Prints the measured numbers; not a test (the numbers depend on the machine; README and
docs/rotating-screws.md quote what it printed).
"""
from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tests" / "cases"), str(ROOT / "analysis")]
from tsg_harness import run_lmp  # noqa: E402

INPUTS = ROOT / "tests" / "cases" / "inputs"
PERIODIC_LENGTH = 0.0958333333333333
TOLERANCES_UM = (20, 5, 1)


def meshes(tolerance_um: int, build: Path) -> Path:
    out = build / "meshes" / f"consigma1-periodic-{tolerance_um}um"
    if not (out / "screw1.stl").exists():
        subprocess.run([sys.executable, "-m", "tsg_meshes", "build", str(ROOT / "meshes/configs/consigma1-periodic.spec"),
                        str(out), "--tolerance", f"{tolerance_um}e-6"], check=True, cwd=ROOT / "meshes")
    return out


def triangles(stl: Path) -> int:
    with stl.open("rb") as handle:
        return sum(line.lstrip().startswith(b"facet") for line in handle)


def atoms(count: int, seed: int = 23) -> str:
    from test_corotating import atoms_in_bores  # the same placement as the force-equality tests
    return atoms_in_bores(np.random.default_rng(seed), count, [(0.0, PERIODIC_LENGTH)])


def loop_time(log: str) -> tuple[float, int]:
    match = re.findall(r"Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps", log)
    seconds, steps = match[-1]
    return float(seconds), int(steps)


def screw_runs(work: Path, mesh_dir: Path, particles: str, steps: int, nprocs: int) -> dict[str, float]:
    """ms per step for drive none / stock / corotating."""
    drives = {"none": work / "drive_none.in", "stock": INPUTS / "drive_stock.in",
              "corotating": INPUTS / "drive_corotating.in"}
    drives["none"].write_text("# no screw contacts: the baseline\n")
    (work / "atoms.in").write_text(particles)
    result = {}
    for name, drive_file in drives.items():
        run = run_lmp((INPUTS / "in.corotating_paths").read_text(), work / name, nprocs=nprocs, timeout=3600, variables={
            "start_file": INPUTS / "start_fresh.in", "restart_file": work / "unused", "mesh_dir": mesh_dir,
            "drive_file": drive_file, "atoms_file": work / "atoms.in", "xlo": 0.0, "xhi": PERIODIC_LENGTH,
            "xbound": "p", "vx": 0.01, "vy": 0.02, "vz": -0.01, "dt": 2e-6, "period": 0.1, "nsteps": steps,
            "restart_every": 0, "out": work / name / "forces.dump", "dump_every": 10 ** 9})
        run.assert_clean()
        seconds, nsteps = loop_time(run.log)
        result[name] = 1e3 * seconds / nsteps
    return result


def case_runs(work: Path, nprocs: int, t_run: float) -> dict[str, float]:
    """ms per step of the periodic demo case (start-up phase only) for each drive."""
    result = {}
    for drive in ("stock", "corotating"):
        out = work / f"case-{drive}"
        subprocess.run([sys.executable, str(ROOT / "cases/run_case.py"), "periodic", "--scale", "demo", "--np", str(nprocs),
                        "--out", str(out), "-v", "screw_drive", drive, "-v", "t_startup", str(t_run),
                        "-v", "t_sample", str(t_run)], check=True, capture_output=True, text=True)
        log = (out / "log.lammps").read_text()
        runs = re.findall(r"Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps", log)
        seconds = sum(float(s) for s, _ in runs)
        steps = sum(int(n) for _, n in runs)
        result[drive] = 1e3 * seconds / steps
    return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--particles", type=int, default=3453, help="particles (periodic demo: 3453)")
    parser.add_argument("--np", type=int, default=1, help="MPI ranks")
    parser.add_argument("--steps", type=int, nargs=3, default=(400, 200, 100),
                        help="steps at 20, 5 and 1 um meshes")
    parser.add_argument("--case-time", type=float, default=0.01, help="simulated s per case phase")
    parser.add_argument("--skip-case", action="store_true")
    parser.add_argument("--build", type=Path, default=ROOT / "build")
    args = parser.parse_args()

    particles = atoms(args.particles)
    rows = []
    with tempfile.TemporaryDirectory(prefix="corotating-bench-") as tmp:
        work = Path(tmp)
        for tolerance, steps in zip(TOLERANCES_UM, args.steps):
            mesh_dir = meshes(tolerance, args.build)
            ntri = triangles(mesh_dir / "screw1.stl")
            sub = work / f"{tolerance}um"
            sub.mkdir()
            start = time.time()
            ms = screw_runs(sub, mesh_dir, particles, steps, args.np)
            stock, corot = ms["stock"] - ms["none"], ms["corotating"] - ms["none"]
            rows.append((ntri, ms, stock, corot))
            print(f"{ntri:>7} triangles/screw, {steps} steps ({time.time() - start:.0f} s): without screws "
                  f"{ms['none']:.3f} ms/step; stock {ms['stock']:.3f}; corotating {ms['corotating']:.3f} ms/step; "
                  f"screw handling stock {stock:.3f} vs corotating {corot:.3f} ms/step = {stock / corot:.1f} x",
                  flush=True)
        print("\n| triangles per screw | stock screw handling, ms/step | corotating, ms/step | speed-up |")
        print("|---|---|---|---|")
        for ntri, _, stock, corot in rows:
            print(f"| {ntri} | {stock:.3f} | {corot:.3f} | {stock / corot:.1f} x |")
        flat = rows[-1][3] / rows[0][3]
        print(f"\ncorotating cost at {rows[-1][0]} vs {rows[0][0]} triangles per screw: {flat:.2f} x "
              f"(stock: {rows[-1][2] / rows[0][2]:.1f} x); {args.particles} particles, {args.np} rank(s)")
        if not args.skip_case:
            case = case_runs(work, args.np, args.case_time)
            print(f"\nperiodic demo case, whole step ({args.np} rank(s), {args.case_time} s start-up + "
                  f"{args.case_time} s sampling): stock {case['stock']:.3f} ms/step, corotating "
                  f"{case['corotating']:.3f} ms/step = {case['stock'] / case['corotating']:.2f} x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
