"""Per-step cost of the measurement styles (fix residence/time, compute element/stats with fix
ave/time, fix massflow/planes) on a granulator-sized run, measured side by side with and without them.

    .venv/bin/python benchmarks/measure_overhead.py [--lmp build/lmp] [--diameter 0.001] [--steps 1000]
                                                    [--repeat 3] [--np 1] [--perf]

The run is the periodic kneading-block domain of the seed paper (Sec. 2.3.3; consigma1-periodic:
C7/6, 6 x 60 deg kneading, C7/6, 95.833 mm, periodic in x) without the screws: the twin-bore box
y in [-22.2, 22.2] mm, z in [-12.5, 12.5] mm with frictional walls, particles filling the lower part
under gravity, with an axial drift and random velocities so that they collide and keep crossing the
zone boundaries and the sensors. Hertz-Mindlin contacts, 8 zones. Every variant runs the same input
from the same particles; the variants are interleaved --repeat times. Two measures per variant:
  - wall clock: LIGGGHTS' "Loop time" of the timed run;
  - CPU time: user + system time of the lmp process(es) for set-up + warm-up + timed run, minus that
    of the same input with a timed run of 0 steps; less sensitive than the wall clock to other jobs
    on a shared machine (time slicing), still sensitive to their use of caches and memory.
The best (least disturbed) and the median of the repeats are printed, as ms/step and as overhead
relative to the run without the styles. `perf record` on one run attributes the time per function
without that noise (docs/measurement.md quotes both).
Not a test: the numbers depend on the machine; docs/measurement.md quotes what it printed.
"""
from __future__ import annotations

import argparse
import math
import os
import re
import resource
import shutil
import statistics
import subprocess
import tempfile
from pathlib import Path

from tsg_cases.launcher import run_lmp

ROOT = Path(__file__).resolve().parents[1]

LENGTH = 0.095833
KNEADING = 0.00625
ZONES = ([(1, "conveying", 0.0, 0.029167)] +
         [(2 + k, "kneading", 0.029167 + k * KNEADING, 0.029167 + (k + 1) * KNEADING) for k in range(6)] +
         [(8, "conveying", 0.029167 + 6 * KNEADING, LENGTH)])
FREE_AREA = 5.5e-4   # m^2, order of the ConsiGma-1 free section; only used to scale the solid fraction

TEMPLATE = """
atom_style granular
atom_modify map array
boundary p f f
newton off
communicate single vel yes
units si
processors * 1 1
region box block 0 {length} -0.0222 0.0222 -0.0125 0.0125 units box
create_box 1 box
neighbor {skin} bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 1.0e7
fix m2 all property/global poissonsRatio peratomtype 0.25
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
fix wall1 all wall/gran model hertz tangential history primitive type 1 yplane -0.0222
fix wall2 all wall/gran model hertz tangential history primitive type 1 yplane 0.0222
fix wall3 all wall/gran model hertz tangential history primitive type 1 zplane -0.0125
fix wall4 all wall/gran model hertz tangential history primitive type 1 zplane 0.0125
lattice sc {spacing}
region fill block 0 {length} -0.0215 0.0215 -0.0118 0.004 units box
create_atoms 1 region fill
set group all diameter {diameter} density 1263
variable vx atom 0.05+0.3*sin(1000*y+2000*z)
variable vy atom 0.3*cos(1300*x+900*z)
variable vz atom 0.3*sin(1700*x+1100*y)
velocity all set v_vx v_vy v_vz units box
fix gravi all gravity 9.81 vector 0 0 -1
fix integr all nve/sphere
timestep {dt}
{measure}
thermo_style custom step atoms ke
thermo 1000000
run 500
run {steps}
"""

VARIANTS = {
    "without": "",
    "residence/time": "fix rt all residence/time zones zones.txt records records.txt periodic 0.0 "
                      "analysis 0.005 0.0908 flush 1000",
    "element/stats (ave/time every 100)": "compute es all element/stats zones zones.txt\n"
                                          "fix avg all ave/time 100 10 1000 c_es[1] c_es[2] c_es[3] c_es[4] c_es[5] "
                                          "mode vector file elements.txt",
    "massflow/planes (2 sensors)": "fix mf all massflow/planes planes 2 0.0 0.06 window 1000 file massflow.txt",
}
VARIANTS["all three"] = "\n".join(v for k, v in VARIANTS.items() if k != "without")


def zones_text() -> str:
    return "# benchmark zones (consigma1-periodic layout)\n" + "".join(
        f"{i} {kind} {a:.6f} {b:.6f} {FREE_AREA * (b - a):.6e}\n" for i, kind, a, b in ZONES)


def loop_time(log: str) -> tuple[float, int, int]:
    """(seconds, steps, atoms) of the last run in a LIGGGHTS log."""
    hits = re.findall(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms", log)
    if not hits:
        raise RuntimeError("no 'Loop time' line in the log")
    seconds, _, steps, atoms = hits[-1]
    return float(seconds), int(steps), int(atoms)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--lmp", default=os.environ.get("TSG_LMP", str(ROOT / "build" / "lmp")))
    parser.add_argument("--diameter", type=float, default=0.001, help="particle diameter, m")
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--np", type=int, default=1, help="MPI ranks")
    parser.add_argument("--perf", action="store_true",
                        help="also run 'all three' once under perf record and print the share of the samples "
                             "in the measurement styles' own functions")
    args = parser.parse_args()
    os.environ["TSG_LMP"] = str(Path(args.lmp).resolve())

    d = args.diameter
    # Rayleigh time of the particle (E = 1e7 Pa, nu = 0.25, 1263 kg/m^3), 20 % of it
    shear = 1.0e7 / 2.5
    rayleigh = math.pi * d / 2 * math.sqrt(1263 / shear) / (0.1631 * 0.25 + 0.8766)
    text_vars = dict(length=LENGTH, skin=0.25 * d, spacing=1.05 * d, diameter=d, dt=0.2 * rayleigh,
                     steps=args.steps)
    wall: dict[str, list[float]] = {name: [] for name in VARIANTS}
    cpu: dict[str, list[float]] = {name: [] for name in VARIANTS}
    atoms = 0

    def cpu_seconds(text: str, workdir: Path) -> tuple[float, str]:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        run = run_lmp(text, workdir, nprocs=args.np, files={"zones.txt": zones_text()})
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), run.log

    with tempfile.TemporaryDirectory(prefix="measure-overhead-") as tmp:
        for r in range(args.repeat):
            for k, (name, measure) in enumerate(VARIANTS.items()):
                full, log = cpu_seconds(TEMPLATE.format(measure=measure, **text_vars), Path(tmp) / f"{r}-{k}")
                setup, _ = cpu_seconds(TEMPLATE.format(measure=measure, **dict(text_vars, steps=0)),
                                       Path(tmp) / f"{r}-{k}-setup")
                seconds, steps, atoms = loop_time(log)
                wall[name].append(seconds / steps)
                cpu[name].append((full - setup) / args.steps)
                print(f"  repeat {r + 1}: {name:38s} wall {1e3 * seconds / steps:8.3f} ms/step, "
                      f"cpu {1e3 * (full - setup) / args.steps:8.3f} ms/step", flush=True)
    print(f"\n{atoms} particles of {1e3 * d:g} mm, {len(ZONES)} zones, {args.steps} steps, {args.np} rank(s), "
          f"{args.repeat} repeats")
    for label, table in (("wall clock (Loop time)", wall), ("CPU time", cpu)):
        best = {name: min(t) for name, t in table.items()}
        median = {name: statistics.median(t) for name, t in table.items()}
        print(f"\n{label}")
        print(f"{'variant':40s} {'best ms/step':>13s} {'overhead':>9s} {'median ms/step':>15s} {'overhead':>9s}")
        for name in VARIANTS:
            print(f"{name:40s} {1e3 * best[name]:13.3f} {100 * (best[name] / best['without'] - 1):8.2f}% "
                  f"{1e3 * median[name]:15.3f} {100 * (median[name] / median['without'] - 1):8.2f}%")
    if args.perf:
        perf_share(text_vars, os.environ["TSG_LMP"])


def perf_share(text_vars: dict, lmp: str) -> None:
    """Runs 'all three' under `perf record` and prints the share of samples in our functions."""
    if not shutil.which("perf"):
        print("\nperf not found: no attribution")
        return
    ours = ("FixResidenceTime", "FixMassflowPlanes", "ComputeElementStats", "tsg::")
    with tempfile.TemporaryDirectory(prefix="measure-perf-") as tmp:
        Path(tmp, "in.all").write_text(TEMPLATE.format(measure=VARIANTS["all three"], **text_vars))
        Path(tmp, "zones.txt").write_text(zones_text())
        subprocess.run(["perf", "record", "-q", "-o", "perf.data", lmp, "-in", "in.all", "-echo", "none",
                        "-log", "none"], cwd=tmp, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        report = subprocess.run(["perf", "report", "-i", "perf.data", "--no-children", "--stdio",
                                 "--percent-limit", "0", "--sort", "symbol"], cwd=tmp, check=True,
                                capture_output=True, text=True).stdout
    total, lines = 0.0, []
    for line in report.splitlines():
        m = re.match(r"\s*([0-9.]+)%\s+\[\.\]\s+(.*)", line)
        if m and any(key in m.group(2) for key in ours):
            total += float(m.group(1))
            lines.append(f"  {float(m.group(1)):6.2f}%  {m.group(2)[:90]}")
    print("\nperf record of 'all three' (set-up, warm-up and timed run): samples in the styles' own code")
    print("\n".join(lines))
    print(f"  {total:6.2f}%  total")


if __name__ == "__main__":
    main()
