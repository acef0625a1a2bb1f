"""Cost of turning the screws: stock `fix move/mesh rotate` + `fix wall/gran` against
`fix wall/gran/corotating`, measured side by side in one invocation.

    .venv/bin/python benchmarks/corotating_screws.py [--particles 3453] [--np 1] [--skip-case]

1. Screw contact handling per step at about 10k, 50k and 200k triangles per screw (the periodic
   ConsiGma-1 screws meshed at 20, 5 and 1 µm) in the periodic demo case itself (cases/in.tsg_periodic,
   its static fill of 3 453 particles of 1 mm falling onto the turning screws): the first steps run
   with the screws turned by the stock path, by the corotating fix, and without screw contacts
   (screw meshes loaded, no wall fix for them), the barrel always through the stock path; the screw
   cost is the step time minus the step time without screw contacts. The fill comes from the 20 µm screws (the finer ones differ by
   less than 20 µm).
2. The whole step of the periodic demo case (cases/run_case.py periodic --scale demo) with either
   drive (cases/include/screws_*.in: the corotating one also takes the barrel through its static
   look-up) over the same short run.
Prints the measured numbers; not a test (the numbers depend on the machine; docs/performance.md
quotes what it printed).
"""
from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from tsg_cases.launcher import lmp_executable, mpi_command

ROOT = Path(__file__).resolve().parents[1]

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


def loop_times(log: str) -> list[tuple[float, int]]:
    return [(float(t), int(n)) for t, n in re.findall(r"Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps", log)]


NO_SCREW_CONTACTS = """# benchmark baseline: the barrel only; the screw meshes are loaded but nothing touches them
fix walls all wall/gran model hertz tangential history rolling_friction cdt mesh n_meshes 1 meshes barrel
variable walls_dump_screws equal 0
"""


SCREWS_ONLY = """# benchmark: the screws through fix wall/gran/corotating, the barrel through the stock path (as in
# the baseline), so that the difference is the screws' alone
fix walls all wall/gran/corotating model hertz tangential history rolling_friction cdt &
    mesh n_meshes 3 meshes screw1 screw2 barrel &
    corotate screw1 origin 0 ${axis1_y} ${axis_z} axis 1 0 0 period ${turn_period} &
    corotate screw2 origin 0 ${axis2_y} ${axis_z} axis 1 0 0 period ${turn_period}
variable walls_dump_screws equal 1
"""


def case_copy(work: Path) -> Path:
    """cases/ with two more drives: screws_none.in (the baseline) and screws_corotating-only.in."""
    copy = work / "cases"
    shutil.copytree(ROOT / "cases", copy, ignore=shutil.ignore_patterns("__pycache__"))
    (copy / "include" / "screws_none.in").write_text(NO_SCREW_CONTACTS)
    (copy / "include" / "screws_corotating-only.in").write_text(SCREWS_ONLY)
    return copy


def fill(work: Path, nprocs: int) -> tuple[Path, dict[str, str]]:
    """The demo fill and the variables run_case.py passes to lmp (from its log)."""
    out = work / "fill"
    subprocess.run([sys.executable, "-m", "tsg_cases.run_case", "periodic", "--scale", "demo", "--np", str(nprocs),
                    "--out", str(out), "-v", "t_startup", "1e-5", "-v", "t_sample", "1e-5"],
                   check=True, capture_output=True, text=True)
    return out / "fill.in", {"d_mean": "0.001", "dt_fraction": "0.2", "domain_length": "0.0958333333333333"}


def screw_runs(work: Path, cases: Path, fill_file: Path, variables: dict[str, str], mesh_dir: Path, steps: int,
               nprocs: int) -> dict[str, float]:
    """ms per step of the first `steps` steps for drive none / stock / corotating (screws only)."""
    result = {}
    for drive, include in (("none", "none"), ("stock", "stock"), ("corotating", "corotating-only")):
        out = work / drive
        out.mkdir(parents=True)
        command = mpi_command(nprocs) + [lmp_executable(), "-in", str(cases / "in.tsg_periodic"), "-log",
                                         str(out / "log.lammps"), "-echo", "none"]
        settings = dict(variables, case_dir=cases, out_dir=out, fill_file=fill_file, mesh_dir=mesh_dir,
                        screw_drive=include, t_startup=f"{steps * 2.5e-6 * 1.0001:.9g}", t_sample="1e-9",
                        thermo_every=steps, stats_every=steps, procs_x=nprocs)
        for name, value in settings.items():
            command += ["-var", name, str(value)]
        proc = subprocess.run(command, capture_output=True, text=True, cwd=out, timeout=3600)
        log = (out / "log.lammps").read_text(errors="replace")
        if proc.returncode != 0:
            raise RuntimeError(f"{drive} at {mesh_dir.name} failed:\n{log[-2000:]}\n{proc.stderr[-2000:]}")
        seconds, nsteps = loop_times(log)[0]
        result[drive] = 1e3 * seconds / nsteps
        if drive == "corotating":  # the fix's own timer: the screws alone (the barrel is not in it here)
            result["timer"] = float(re.search(r"contact handling ([0-9.eE+-]+) ms/step", log).group(1))
    return result


def case_runs(work: Path, nprocs: int, t_run: float) -> dict[str, float]:
    """ms per step of the periodic demo case (start-up phase only) for each drive."""
    result = {}
    for drive in ("stock", "corotating"):
        out = work / f"case-{drive}"
        subprocess.run([sys.executable, "-m", "tsg_cases.run_case", "periodic", "--scale", "demo", "--np", str(nprocs),
                        "--out", str(out), "-v", "screw_drive", drive, "-v", "t_startup", str(t_run),
                        "-v", "t_sample", str(t_run)], check=True, capture_output=True, text=True)
        log = (out / "log.lammps").read_text()
        runs = loop_times(log)
        seconds = sum(t for t, _ in runs)
        steps = sum(n for _, n in runs)
        result[drive] = 1e3 * seconds / steps
    return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--np", type=int, default=1, help="MPI ranks")
    parser.add_argument("--steps", type=int, nargs=3, default=(2000, 2000, 2000),
                        help="steps at 20, 5 and 1 um meshes")
    parser.add_argument("--case-time", type=float, default=0.01, help="simulated s per case phase")
    parser.add_argument("--skip-case", action="store_true")
    parser.add_argument("--build", type=Path, default=ROOT / "build")
    args = parser.parse_args()

    rows = []
    with tempfile.TemporaryDirectory(prefix="corotating-bench-") as tmp:
        work = Path(tmp)
        cases = case_copy(work)
        fill_file, variables = fill(work, args.np)
        for tolerance, steps in zip(TOLERANCES_UM, args.steps):
            mesh_dir = meshes(tolerance, args.build)
            ntri = triangles(mesh_dir / "screw1.stl")
            start = time.time()
            ms = screw_runs(work / f"{tolerance}um", cases, fill_file, variables, mesh_dir, steps, args.np)
            stock, corot = ms["stock"] - ms["none"], ms["corotating"] - ms["none"]
            rows.append((ntri, ms, stock, corot))
            print(f"{ntri:>7} triangles/screw, {steps} steps ({time.time() - start:.0f} s): without screw contacts "
                  f"{ms['none']:.3f} ms/step; stock {ms['stock']:.3f}; corotating {ms['corotating']:.3f} ms/step "
                  f"(its timer: {ms['timer']:.3f}); screw handling stock {stock:.3f} vs corotating {corot:.3f} "
                  f"ms/step = {stock / corot:.1f} x", flush=True)
        print("\nscrew handling = step time minus the step time without screw contacts; timer = the corotating "
              "fix's own time (screws only)")
        print("| triangles per screw | stock, ms/step | corotating, ms/step | speed-up | corotating timer, ms/step |")
        print("|---|---|---|---|---|")
        for ntri, ms, stock, corot in rows:
            print(f"| {ntri} | {stock:.3f} | {corot:.3f} | {stock / corot:.1f} x | {ms['timer']:.3f} |")
        print(f"\nfrom {rows[0][0]} to {rows[-1][0]} triangles per screw: corotating x {rows[-1][3] / rows[0][3]:.2f} "
              f"(timer x {rows[-1][1]['timer'] / rows[0][1]['timer']:.2f}), stock x {rows[-1][2] / rows[0][2]:.1f}; "
              f"periodic demo fill, 3 453 particles, {args.np} rank(s)")
        if not args.skip_case:
            case = case_runs(work, args.np, args.case_time)
            print(f"\nperiodic demo case, whole step ({args.np} rank(s), {args.case_time} s start-up + "
                  f"{args.case_time} s sampling): stock {case['stock']:.3f} ms/step, corotating "
                  f"{case['corotating']:.3f} ms/step = {case['stock'] / case['corotating']:.2f} x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
