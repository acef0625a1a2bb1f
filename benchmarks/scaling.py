"""Strong scaling of the periodic case: the same state on 1, 2, 4, ... ranks in one invocation.

    .venv/bin/python benchmarks/scaling.py [--scales demo paper] [--np 1 2 4 8 16] [--steps 2000 300]
        [--repeat 3] [--work DIR] [--json FILE]

For each scale (cases/run_case.py --scale demo: 3 453 particles of 1 mm, 4 um meshes; paper: 63 320
of 400 um (2.7 g), 1 um meshes) the case is prepared and its state in motion made once: the demo's kept
steady state, the paper case run 0.1 s from its fill (benchmarks/paper_cost.py: prepare, motion_restart;
kept in --work between calls; --restart SCALE FILE takes another).
Then each rank count reads that restart and runs the first --steps steps of the case as it is
(`processors N 1 1`, slabs along the screw axis; LIGGGHTS-PUBLIC has no load balancing), rank
counts interleaved within each repeat. Printed per scale: ms/step (LIGGGHTS' loop time, median and
range over the repeats), speed-up and parallel efficiency against 1 rank (from the medians).
Ranks beyond the machine's cores are oversubscribed and then measure nothing useful: run the
rank counts the machine has cores for (a 16-core node: --np 1 2 4 8 16).
Not a test: wall-clock numbers depend on the machine and its load (recorded in the output).
"""
from __future__ import annotations

import argparse
import json
import os
import shlex
import statistics
import sys
import tempfile
from pathlib import Path

# a sibling (python puts the script's folder first on its path): prepare, motion_restart, bench, machine
import paper_cost

ROOT = paper_cost.ROOT


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--lmp", default=os.environ.get("TSG_LMP", str(ROOT / "build" / "lmp")))
    parser.add_argument("--scales", nargs="+", choices=sorted(paper_cost.SCALES), default=["demo", "paper"])
    parser.add_argument("--np", type=int, nargs="+", default=[1, 2, 4, 8, 16])
    parser.add_argument("--steps", type=int, nargs="+", default=[1000, 300], help="steps per run, one per scale")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--thermo-every", type=int, default=100)
    parser.add_argument("--restart", nargs=2, action="append", default=[], metavar=("SCALE", "FILE"),
                        help="a restart in motion to use for SCALE instead of making one")
    parser.add_argument("--work", type=Path, default=None, help="keeps the prepared fills and restarts between calls")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    if len(args.steps) != len(args.scales):
        parser.error(f"--steps takes one value per scale ({len(args.scales)}), got {len(args.steps)}")
    for steps in args.steps:  # the guards' fix is computed every thermo_every steps; thermo prints the last step
        if steps % args.thermo_every:
            parser.error(f"--steps {steps} is not allowed: a multiple of --thermo-every {args.thermo_every}")
    if 1 not in args.np:
        parser.error("--np must include 1 (the speed-up is against 1 rank)")
    work = args.work or Path(tempfile.mkdtemp(prefix="scaling_"))
    work.mkdir(parents=True, exist_ok=True)
    given_restarts = {scale: Path(file) for scale, file in args.restart}
    machine_at_start = paper_cost.machine()
    print(f"command: {' '.join(shlex.quote(a) for a in [sys.executable] + sys.argv)}")
    print(f"machine: {machine_at_start}", flush=True)
    report = []
    for scale, steps in zip(args.scales, args.steps):
        case = paper_cost.prepare(work, args.lmp, scale)
        restart = given_restarts.get(scale) or paper_cost.motion_restart(work, args.lmp, case, None, args.thermo_every)
        ms: dict[int, list[float]] = {n: [] for n in args.np}
        atoms = 0
        for repeat in range(args.repeat):
            for np_ranks in args.np:
                result, _ = paper_cost.bench("this", args.lmp, np_ranks, restart, case, steps, args.thermo_every,
                                             work / f"scaling-{scale}-np{np_ranks}-{repeat}")
                ms[np_ranks].append(1e3 * result.loop_s / result.steps)
                atoms = result.atoms
                print(f"  {scale} #{repeat} {np_ranks} rank(s): {ms[np_ranks][-1]:.3f} ms/step", flush=True)
        serial = statistics.median(ms[1])
        rows = [{"np": n, "ms_per_step": {"min": min(v), "median": statistics.median(v), "max": max(v), "n": len(v)},
                 "speed_up": serial / statistics.median(v), "efficiency": serial / statistics.median(v) / n}
                for n, v in ms.items()]
        report.append({"scale": scale, "atoms": atoms, "steps": steps, "restart": str(restart), "rows": rows})
        print(f"\n{scale} scale, {atoms} particles, {steps} steps from a restart in motion, {args.repeat} repeat(s):")
        print("| ranks | ms/step (median; min-max) | speed-up | efficiency |")
        print("|---|---|---|---|")
        for row in rows:
            t = row["ms_per_step"]
            print(f"| {row['np']} | {t['median']:.2f} ({t['min']:.2f}-{t['max']:.2f}) | {row['speed_up']:.2f} | "
                  f"{row['efficiency']:.2f} |")
        print(flush=True)
    machine_at_end = paper_cost.machine()
    print(f"machine at the end: {machine_at_end}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"command": [sys.executable] + sys.argv, "machine_at_start": machine_at_start,
                                         "machine_at_end": machine_at_end, "lmp": args.lmp, "scales": report},
                                        indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
