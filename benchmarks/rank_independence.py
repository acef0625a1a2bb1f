"""Rank-count independence of the per-element results (issue 17 item 4, docs/parallel.md): the
periodic demo case from one fill (one --seed) run on 1, 2, 4 and 8 ranks, each compared with the
1-rank run quantity by quantity (mass flows, residence times, solid fraction per element):
difference ± 95 % interval from tsg_analysis.uncertainty (docs/statistics.md).

    .venv/bin/python benchmarks/rank_independence.py --out runs/ranks [--np 1 2 4 8] [--seed 12345]
        [--balance-every 1000] [-v NAME VALUE ...]

Free-flowing DEM is chaotic: different rank counts sum contact forces in a different order, the
trajectories part after a few thousand steps, and the runs become statistically independent
realisations of the same process. Independence of the rank count therefore means: no difference
resolved beyond its interval. Runs that already exist in --out (a summary was written) are reused,
so an interrupted invocation continues. Exit status 1 when a difference is significant.
Not a ctest test (minutes to hours per run); tests/cases/test_rank_independence.py checks the
deterministic part (identical records and sensor counts) in a minute.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

from tsg_analysis.summary import compare_runs, sweep_markdown, write_sweep_csv

ROOT = Path(__file__).resolve().parents[1]


def run_case(out: Path, nprocs: int, seed: int, balance_every: int, extra: list[tuple[str, str]]) -> float:
    """Run the periodic demo case on nprocs ranks in out; the wall seconds it took (0 if reused)."""
    if (out / "log.lammps").exists() and "TSG-DONE" in (out / "log.lammps").read_text(errors="replace"):
        return 0.0
    command = [sys.executable, "-m", "tsg_cases.run_case", "periodic", "--scale", "demo", "--out", str(out),
               "--np", str(nprocs), "--seed", str(seed), "-v", "balance_every", str(balance_every)]
    for name, value in extra:
        command += ["-v", name, value]
    start = time.monotonic()
    subprocess.run(command, check=True)
    return time.monotonic() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--np", type=int, nargs="+", default=[1, 2, 4, 8])
    parser.add_argument("--seed", type=int, default=12345)
    parser.add_argument("--balance-every", type=int, default=1000)
    parser.add_argument("-v", "--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"))
    args = parser.parse_args(argv)
    if any(n < 1 for n in args.np):
        parser.error(f"--np {' '.join(map(str, args.np))} is not allowed: rank counts >= 1")
    runs = {}
    for nprocs in args.np:
        out = args.out / f"np{nprocs}"
        seconds = run_case(out, nprocs, args.seed, args.balance_every, args.var)
        print(f"np {nprocs}: {out} ({'reused' if seconds == 0 else f'{seconds:.0f} s wall, under the load of the moment'})",
              flush=True)
        runs[nprocs] = out
    reference, *others = args.np
    rows = compare_runs([runs[reference]], {f"np{n}": [runs[n]] for n in others})
    table = sweep_markdown(rows)
    print(f"\nagainst np {reference}:\n{table}")
    (args.out / "comparison.md").write_text(table)
    write_sweep_csv(rows, args.out / "comparison.csv")
    significant = [r for r in rows if r.difference.significant]
    unresolved = sum(not r.difference.inputs_resolved for r in rows)
    print(f"{len(rows)} comparisons, {len(significant)} significant, {unresolved} with too few independent samples")
    return 1 if significant else 0


if __name__ == "__main__":
    sys.exit(main())
