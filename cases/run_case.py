"""Prepare and run one granulator case, then print its summary table.

    .venv/bin/python cases/run_case.py periodic --scale demo --out runs/periodic-demo [--np 2] [-v name value ...]

Preparation: builds the meshes the scale needs (meshes/, gmsh) and, for the periodic case, places
the hold-up mass in the free space (cases/free_space.py). Then runs `lmp -in cases/in.tsg_<case>`
(under mpirun with --np > 1) with the scale's variables plus yours (-v overrides any of them), and
prints mass flow at both sensors, mean residence time per element type and the time-averaged solid
fraction per element. Exit status 1 when lmp fails (the error is printed) or when particles escaped.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "analysis"), str(ROOT / "meshes"), str(ROOT / "cases")]
from tsg_analysis.liggghts_log import parse_errors, parse_thermo  # noqa: E402
from tsg_analysis.run_files import (ELEMENT_TYPES, AnalysisInputError, read_element_statistics,  # noqa: E402
                                    read_massflow, read_residence, read_zones)

CONFIGS = {"periodic": "consigma1-periodic", "nonperiodic": "consigma1-nonperiodic", "full": "consigma1-full"}
# Scales. demo: coarse particles so that the periodic case gives per-element results in minutes on
# 2 cores (docs/cases.md explains the choices); paper: the seed paper's 400 um particles. Both with
# the mesh tolerance at 1 % of the smallest radius (demo 0.42 mm -> 4 um, paper 0.1 mm -> 1 um).
SCALES = {
    "demo": {"tolerance": 4e-6,
             "vars": {"d_mean": 0.001, "dt_fraction": 0.2, "thermo_every": 2000, "stats_every": 2000},
             "times": {"periodic": {"t_startup": 0.1, "t_sample": 0.2}, "nonperiodic": {"t_run": 0.5},
                       "full": {"t_sample": 0.5, "t_max_startup": 10.0}}},
    "paper": {"tolerance": 1e-6,
              "vars": {"d_mean": 0.0004, "dt_fraction": 0.1, "thermo_every": 10000, "stats_every": 10000},
              "times": {"periodic": {"t_startup": 0.5, "t_sample": 1.0}, "nonperiodic": {"t_run": 5.0},
                        "full": {"t_sample": 1.0, "t_max_startup": 10.0}}},
}
# Hold-up of the periodic domain: its free volume (435.26 mm² x 95.83 mm = 41.7 cm³) at the mean
# solid fraction of the full granulator at 14.4 kg/h (about 0.044: 12 g over 500 mm, Section 3)
# gives 2.3 g. Override with --holdup-g (e.g. from a full run's hold-up summary).
DEFAULT_HOLDUP_G = 2.3


def build_meshes(config: str, tolerance: float) -> Path:
    from tsg_meshes.build import tolerance_tag
    out = ROOT / "build" / "meshes" / f"{config}-{tolerance_tag(tolerance)}"
    if not (out / "zones.txt").is_file():
        subprocess.run([sys.executable, "-m", "tsg_meshes", "build", config, str(out), "--tolerance", str(tolerance)],
                       check=True, env=dict(os.environ, PYTHONPATH=str(ROOT / "meshes")))
    return out


def lmp_command(np_ranks: int) -> list[str]:
    lmp = os.environ.get("TSG_LMP", str(ROOT / "build" / "lmp"))
    if np_ranks <= 1:
        return [lmp]
    return ["mpirun", "-np", str(np_ranks), "--oversubscribe", "--allow-run-as-root", "--bind-to", "none", lmp]


def summary(out: Path, zones_file: Path) -> str:
    """The short table of the main job; a part whose file has no data yet says so."""
    zones = read_zones(zones_file)
    lines: list[str] = []

    def section(title: str, body) -> None:
        lines.append(title)
        try:
            lines.extend(body())
        except AnalysisInputError as problem:
            lines.append(f"  (not available: {problem})")

    def flows() -> list[str]:
        flow = read_massflow(out / "massflow.txt")
        if len(flow.flow) == 0:
            raise AnalysisInputError(f"{out / 'massflow.txt'}: no complete window yet")
        return [f"  MFS_{k + 1}  {value:9.3f}" for k, value in enumerate(flow.flow.mean(axis=0))]

    def residence() -> list[str]:
        # Two estimates: the records of complete passes/exits (needs a window longer than a pass),
        # and hold-up over throughput per element, τ_e = L_e / v̄_x,e (Little's law, steady state).
        records = read_residence(out / "residence.txt")
        complete = np.isin(records.exit_reason, ("outlet", "pass"))
        stats = read_element_statistics(out / "elements.txt")
        mass = stats.column("mass").sum(axis=0)
        axial = (stats.column("mean_axial_velocity") * stats.column("mass")).sum(axis=0) / np.where(mass > 0, mass, 1)
        length = zones.x_end - zones.x_start
        little = np.where(axial > 0, length / np.where(axial > 0, axial, 1), np.inf)
        rows = [f"  {'':<12}{'records':>9}{'L/v':>9}   ({int(complete.sum())} complete records)"]
        kinds = np.asarray(zones.kind)
        for kind in [t for t in ELEMENT_TYPES if t in zones.kind] + ["total"]:
            values = records.residence_time[complete] if kind == "total" else records.time_by_type[kind][complete]
            estimate = little.sum() if kind == "total" else little[kinds == kind].sum()
            recorded = f"{values.mean():9.4f}" if values.size else f"{'-':>9}"
            rows.append(f"  {kind:<12}{recorded}{estimate:9.4f}")
        return rows

    def elements() -> list[str]:
        stats = read_element_statistics(out / "elements.txt")
        solid = stats.column("solid_fraction").mean(axis=0)
        mass = stats.column("mass").sum(axis=0)
        axial = (stats.column("mean_axial_velocity") * stats.column("mass")).sum(axis=0) / np.where(mass > 0, mass, 1)
        return [f"  {label:<5}{kind:<12}{fraction:>16.4f}{velocity:>22.4f}"
                for label, kind, fraction, velocity in zip(zones.labels, zones.kind, solid, axial)]

    section("mass flow at the sensors (kg/h, mean over the sampling window)", flows)
    section("residence time per element type (s): mean of complete records | hold-up/throughput L/v", residence)
    section("per element (time averages)   solid fraction   axial velocity (m/s)", elements)
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("case", choices=sorted(CONFIGS))
    parser.add_argument("--scale", choices=sorted(SCALES), default="demo")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--np", type=int, default=1, help="MPI ranks")
    parser.add_argument("--holdup-g", type=float, help="hold-up mass of the periodic domain, g")
    parser.add_argument("--seed", type=int, default=12345, help="seed of the static fill")
    parser.add_argument("--feed-at", default="inlet",
                        help="where particles are generated (full case): 'inlet' or 'element:N' (zone N, e.g. element:7 as the paper)")
    parser.add_argument("--mesh-tolerance", type=float,
                        help="mesh tolerance in m instead of the scale's (1 %% of the smallest radius)")
    parser.add_argument("-v", "--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"))
    args = parser.parse_args(argv)
    if args.mesh_tolerance is not None and not 0.0 < args.mesh_tolerance < 1e-3:
        parser.error(f"--mesh-tolerance {args.mesh_tolerance} is not allowed: a length in m, 0 < tolerance < 1e-3")
    scale = SCALES[args.scale]
    variables = {**scale["vars"], **scale["times"][args.case], **dict(args.var)}
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    mesh_dir = build_meshes(CONFIGS[args.case], args.mesh_tolerance or scale["tolerance"])
    zones = read_zones(mesh_dir / "zones.txt")
    length = float(zones.x_end[-1])
    import free_space
    d_mean = float(variables["d_mean"])
    if args.case == "periodic":
        holdup = (args.holdup_g or DEFAULT_HOLDUP_G) * 1e-3
        centres, diameters = free_space.fill(mesh_dir, holdup, d_mean, float(variables.get("psd_sigma", 0.05)),
                                             1263.0, (0.0, length), True, args.seed)
        (out / "fill.in").write_text(free_space.fill_include(centres, diameters, 1263.0, str(mesh_dir)))
        variables["fill_file"] = out / "fill.in"
        what = f"{len(diameters)} particles ({holdup * 1e3:.3g} g)"
    else:
        if args.feed_at == "inlet":
            x0 = 0.002
        elif args.feed_at.startswith("element:") and args.feed_at[8:].isdigit() \
                and 1 <= int(args.feed_at[8:]) <= len(zones):
            x0 = float(zones.x_start[int(args.feed_at[8:]) - 1])
        else:
            parser.error(f"--feed-at {args.feed_at}: use 'inlet' or 'element:N' with 1 <= N <= {len(zones)}")
        side = 1.6 * 1.5 * d_mean          # cube edge: 1.6 x the largest particle of the PSD
        corners = free_space.feed_boxes(mesh_dir, (x0, x0 + 0.028), side, 0.1 * d_mean)
        (out / "feed.in").write_text(free_space.feed_include(corners, side, str(mesh_dir)))
        variables["feed_file"] = out / "feed.in"
        what = f"feed region of {len(corners)} cubes at x = {x0 * 1e3:.1f}-{(x0 + 0.028) * 1e3:.1f} mm"
    # the run directory is self-describing for tsg_analysis: zones and screw surfaces next to the outputs
    shutil.copyfile(mesh_dir / "zones.txt", out / "zones.txt")
    (out / "meshes").mkdir(exist_ok=True)
    for name in ("screw1.stl", "screw2.stl"):
        link = out / "meshes" / name
        link.unlink(missing_ok=True)
        link.symlink_to(mesh_dir / name)
    variables.update({"case_dir": ROOT / "cases", "out_dir": out, "mesh_dir": mesh_dir,
                      "domain_length": repr(length)})
    if args.np > 1:
        variables.setdefault("procs_x", args.np)
    command = lmp_command(args.np) + ["-in", str(ROOT / "cases" / f"in.tsg_{args.case}"), "-log", "log.lammps", "-echo", "none"]
    for name, value in variables.items():
        command += ["-var", name, str(value)]
    print(f"[run] {args.case} case, {args.scale} scale: {what}, meshes {mesh_dir.name}, output {out}", flush=True)
    start = time.perf_counter()
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    with open(out / "screen.txt", "w") as screen:
        proc = subprocess.run(command, cwd=out, stdout=screen, stderr=subprocess.STDOUT, env=env)
    wall = time.perf_counter() - start
    log = (out / "log.lammps").read_text(errors="replace") if (out / "log.lammps").exists() else ""
    if proc.returncode != 0:
        errors = parse_errors(log + (out / "screen.txt").read_text(errors="replace"))
        print(f"[run] lmp failed (exit {proc.returncode}): {errors[-1] if errors else 'see ' + str(out / 'screen.txt')}",
              file=sys.stderr)
        return 1
    thermo = parse_thermo(log)
    steps = int(sum(block["Step"][-1] - block["Step"][0] for block in thermo))
    print(f"[run] done in {wall:.0f} s ({steps} steps, {wall / max(steps, 1) * 1e3:.2f} ms/step)")
    print(summary(out, mesh_dir / "zones.txt"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
