"""Memory per MPI rank of the screw and barrel meshes: peak resident memory (VmHWM) of every rank of
`lmp` with the case's meshes loaded and one particle, at several rank counts and mesh tolerances.

    .venv/bin/python benchmarks/memory.py [--np 1 2 4 8] [--meshes consigma1-periodic-1um ...]
        [--variants box meshes corotating] [--json FILE]

Each run is the case's domain (the mesh directory's machine.in, `processors N 1 1` along the screw
axis), the case's materials and models, one particle, then one of
- box: no meshes (the lmp process itself: MPI, LIGGGHTS, the pair style);
- meshes: the three `fix mesh/surface` (LIGGGHTS' own mesh storage, decomposed by LIGGGHTS over
  the ranks, plus what the STL import leaves behind);
- corotating: the meshes plus `fix wall/gran/corotating` as the cases use it (cases/include/
  screws_corotating.in): its static copy of every triangle (in the screw's own frame) and the
  bounding-volume tree, held whole on every rank;
and `run 1`. Each rank is wrapped in /usr/bin/time, whose "maximum resident set size" is the
rank's VmHWM (peak, including the transient memory of reading the STL files). Also printed:
LIGGGHTS' own report ("Memory usage per processor": atoms, neighbour lists and the fixes'
memory_usage(), which for fix wall/gran/corotating counts its triangles, tree and coplanar lists;
fix mesh/surface reports nothing) and, as an independent estimate, the fix's triangle storage from
the triangle count and the layout of tsg::trimesh::Triangle and TriangleTree.
Not a test: the numbers depend on the allocator and the MPI library; they do not depend on load.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import re
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"

# Bytes per triangle held by fix wall/gran/corotating (src-liggghts-eepa/physics/triangle_lookup.h):
# Triangle (216 B: 24 doubles, an int, a double, 6 bools, padded), the tree's bounding sphere
# (4 doubles), its order index (int) and its nodes (at most n/2 + 2 nodes of 72 B: reserved up front).
FIX_BYTES_PER_TRIANGLE = 216 + 4 * 8 + 4 + 72 / 2

INPUT = """# benchmarks/memory.py: the case's domain, models and meshes with one particle
include ${mesh_dir}/machine.in
atom_style    granular
atom_modify   map array
boundary      ${boundary_x} f f
newton        off
communicate   single vel yes
units         si
processors    * 1 1
region        box block ${x_lo} ${x_hi} -${box_y} ${box_y} -${box_z} ${box_z} units box
create_box    2 box
include ${case_dir}/include/materials.in
include ${case_dir}/include/models.in
variable d_min equal ${d_mean}
create_atoms  1 single $(0.5*(v_x_lo+v_x_hi)) 0 $(v_axis_z+0.5*v_box_z) units box   # LIGGGHTS wants type 1 present
set           atom 1 diameter ${d_mean} density ${rho_p}
timestep 1e-7
include ${variant_file}
run 1
"""

MESHES_ONLY = """fix screw1 all mesh/surface file ${mesh_dir}/screw1.stl type 2
fix screw2 all mesh/surface file ${mesh_dir}/screw2.stl type 2
fix barrel all mesh/surface file ${mesh_dir}/barrel.stl type 2
"""

COROTATING = MESHES_ONLY + """variable turn_period equal 0.1
fix walls all wall/gran/corotating model hertz tangential history rolling_friction cdt &
    mesh n_meshes 3 meshes screw1 screw2 barrel &
    corotate screw1 origin 0 ${axis1_y} ${axis_z} axis 1 0 0 period ${turn_period} &
    corotate screw2 origin 0 ${axis2_y} ${axis_z} axis 1 0 0 period ${turn_period} &
    fixed barrel
"""

VARIANTS = {"box": "", "meshes": MESHES_ONLY, "corotating": COROTATING}


def triangles(stl: Path) -> int:
    with stl.open("rb") as handle:
        return sum(line.lstrip().startswith(b"facet") for line in handle)


def x_range(mesh_dir: Path) -> tuple[float, float]:
    """The axial span of the zones file (the box along x)."""
    rows = [line.split() for line in (mesh_dir / "zones.txt").read_text().splitlines()
            if line.strip() and not line.startswith("#")]
    return float(rows[0][2]), float(rows[-1][3])


def run(mesh_dir: Path, variant: str, np_ranks: int, work: Path, lmp: str, collect: bool) -> dict[str, object] | None:
    out = work / f"{mesh_dir.name}-{variant}-np{np_ranks}"
    if collect:   # what an earlier, interrupted invocation left in --work, or nothing
        done_ranks = all((out / f"hwm.{rank}").exists() and (out / f"hwm.{rank}").read_text().strip()
                         for rank in range(np_ranks))
        return measured(out, mesh_dir, variant, np_ranks, float("nan")) if done_ranks else None
    out.mkdir(parents=True, exist_ok=True)
    (out / "in.memory").write_text(INPUT)
    (out / "variant.in").write_text(VARIANTS[variant])
    x_lo, x_hi = x_range(mesh_dir)
    periodic = "periodic" in mesh_dir.name
    margin = 0.0 if periodic else 0.002   # the non-periodic barrel ends lie on the zones' ends
    variables = {"mesh_dir": mesh_dir, "case_dir": CASES, "variant_file": out / "variant.in",
                 "boundary_x": "p" if periodic else "f", "x_lo": x_lo - margin, "x_hi": x_hi + margin,
                 "d_mean": 0.0004, "skin": 0.00008, "cohesion": 0}
    # every rank under /usr/bin/time: "%M" is its maximum resident set size (VmHWM), KiB
    timed = ["sh", "-c", 'exec /usr/bin/time -f %M -o "$0/hwm.${OMPI_COMM_WORLD_RANK:-0}" "$@"', str(out), lmp]
    command = (["mpirun", "-np", str(np_ranks), "--oversubscribe", "--allow-run-as-root", "--bind-to", "none"]
               if np_ranks > 1 else []) + timed + ["-in", "in.memory", "-log", "log.lammps", "-echo", "none"]
    for name, value in variables.items():
        command += ["-var", name, str(value)]
    start = time.perf_counter()
    done = subprocess.run(command, cwd=out, capture_output=True, text=True, errors="replace",
                          env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    if done.returncode != 0:
        log = (out / "log.lammps").read_text(errors="replace") if (out / "log.lammps").exists() else ""
        raise SystemExit(f"lmp failed in {out} (exit {done.returncode}):\n{log[-2000:]}\n{done.stderr[-2000:]}")
    return measured(out, mesh_dir, variant, np_ranks, time.perf_counter() - start)


def measured(out: Path, mesh_dir: Path, variant: str, np_ranks: int, wall_s: float) -> dict[str, object]:
    hwm_mb = [int((out / f"hwm.{rank}").read_text().split()[-1]) / 1024 for rank in range(np_ranks)]
    report = re.findall(r"Memory usage per processor = (\S+) Mbytes", (out / "log.lammps").read_text(errors="replace"))
    return {"mesh": mesh_dir.name, "variant": variant, "np": np_ranks, "hwm_mb_per_rank": hwm_mb,
            "hwm_mb_max": max(hwm_mb), "hwm_mb_mean": statistics.fmean(hwm_mb), "hwm_mb_node": sum(hwm_mb),
            "liggghts_report_mb": float(report[-1]), "wall_s": wall_s}


def machine() -> str:
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    mpi = subprocess.run(["mpirun", "--version"], capture_output=True, text=True).stdout.splitlines()[:1]
    return f"{platform.node()}, {os.cpu_count()} cores, {' '.join(mpi)}, commit {commit}, " \
           f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--lmp", default=os.environ.get("TSG_LMP", str(ROOT / "build" / "lmp")))
    parser.add_argument("--np", type=int, nargs="+", default=[1, 2, 4, 8])
    parser.add_argument("--meshes", nargs="+", default=["consigma1-periodic-20um", "consigma1-periodic-4um",
                                                       "consigma1-periodic-1um", "consigma1-full-4um"],
                        help="mesh directories under build/meshes (make them with python -m tsg_meshes build)")
    parser.add_argument("--variants", nargs="+", choices=sorted(VARIANTS), default=["box", "meshes", "corotating"])
    parser.add_argument("--variant-np", type=int, nargs="+", default=None,
                        help="rank counts for the box and meshes variants (default: --np)")
    parser.add_argument("--work", type=Path, default=None)
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--collect", action="store_true",
                        help="run nothing: read what an earlier invocation with the same options left in --work")
    args = parser.parse_args(argv)
    work = args.work or Path(tempfile.mkdtemp(prefix="memory_"))
    print(f"command: {' '.join(shlex.quote(a) for a in [sys.executable] + sys.argv)}")
    print(f"machine: {machine()}", flush=True)
    rows = []
    print(f"{'mesh':<26}{'triangles':>10}{'variant':>12}{'ranks':>6}{'MB/rank max':>12}{'MB/rank mean':>13}"
          f"{'MB all ranks':>13}{'LIGGGHTS MB':>12}{'fix layout MB':>14}")
    for name in args.meshes:
        mesh_dir = Path(name) if "/" in name else ROOT / "build" / "meshes" / name
        name = mesh_dir.name
        ntri = {part: triangles(mesh_dir / f"{part}.stl") for part in ("screw1", "screw2", "barrel")}
        fix_mb = sum(ntri.values()) * FIX_BYTES_PER_TRIANGLE / 2**20
        for variant in args.variants:
            for np_ranks in (args.np if variant == "corotating" or not args.variant_np else args.variant_np):
                row = run(mesh_dir, variant, np_ranks, work, args.lmp, args.collect)
                if row is None:
                    continue
                row.update(triangles=ntri, fix_copy_mb=fix_mb if variant == "corotating" else 0.0)
                rows.append(row)
                print(f"{name:<26}{sum(ntri.values()):>10}{variant:>12}{np_ranks:>6}{row['hwm_mb_max']:>12.1f}"
                      f"{row['hwm_mb_mean']:>13.1f}{row['hwm_mb_node']:>13.1f}{row['liggghts_report_mb']:>12.1f}"
                      f"{row['fix_copy_mb']:>14.1f}", flush=True)
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"command": [sys.executable] + sys.argv, "machine": machine(),
                                         "collected": "read from what an earlier invocation left in --work"
                                         if args.collect else None,
                                         "fix_bytes_per_triangle": FIX_BYTES_PER_TRIANGLE, "runs": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
