"""Rank-count independence of the per-element results (docs/performance.md): the
periodic demo case from one fill (one --seed) run on 1, 2, 4 and 8 ranks, each compared with the
1-rank run quantity by quantity (mass flows, residence times, solid fraction per element):
difference ± 95 % interval from tsg_analysis.uncertainty (docs/statistics.md).

    .venv/bin/python benchmarks/rank_independence.py --out runs/ranks [--np 1 2 4 8] [--seed 12345]
        [--balance-every 1000] [--replicas DIR ...] [-v NAME VALUE ...]

Free-flowing DEM is chaotic: different rank counts sum contact forces in a different order, the
trajectories part after a few thousand steps, and the runs become statistically independent
realisations of the same process. Independence of the rank count therefore means: no difference
resolved beyond its interval. Runs that already exist in --out (a summary was written) are reused,
so an interrupted invocation continues. Exit status 1 when a difference is significant.

With --replicas (runs of the same case on the first rank count with other fill seeds, e.g. the
seed-N directories of cases/seed_check.py), each run on another rank count is also tested against
the replica population: its window mean of every quantity against the 95 % prediction interval of
the replicas' window means (tsg_analysis.uncertainty.replica_outlier). This needs no time-series
interval, so it holds for windows too short for one. About 5 % of the tests fall outside by
chance; the exit status is 1 when more do than a binomial test allows (p < 0.01).
Not a ctest test (minutes to hours per run); tests/cases/test_rank_independence.py checks the
deterministic part (identical records and sensor counts) in a minute.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from tsg_analysis.run import Run
from tsg_analysis.summary import compare_runs, summarise, sweep_markdown, write_sweep_csv
from tsg_analysis.uncertainty import replica_outlier

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


def replica_test(replicas: list[Path], others: dict[int, Path]) -> bool:
    """Every quantity of each run in `others` against the replicas' 95 % prediction interval; prints
    the table and the count outside; True when more fall outside than chance allows (p < 0.01)."""
    from scipy.stats import binomtest

    population = [summarise(Run(d)) for d in replicas]
    keys = [(r.quantity, r.scope) for r in population[0].rows]
    print(f"\nagainst {len(replicas)} replicas (window means; 95 % prediction interval):")
    tests = outside = 0
    for nprocs, run_dir in others.items():
        run = summarise(Run(run_dir))
        for key in keys:
            estimates = [s.get(*key) for s in population]
            value = run.get(*key)
            if value is None or any(e is None or not np.isfinite(e.mean) for e in estimates) or not np.isfinite(value.mean):
                continue
            statistic, limit = replica_outlier([e.mean for e in estimates], value.mean)  # type: ignore[union-attr]
            tests += 1
            outside += abs(statistic) > limit
            print(f"  np {nprocs:>2} {key[0]:<28} {key[1]:<26} {value.mean:>11.4g}  t {statistic:+6.2f}"
                  f"  {'OUTSIDE' if abs(statistic) > limit else 'inside'} (|t| <= {limit:.2f})")
    if tests == 0:
        print("  no quantity in common")
        return False
    p_value = binomtest(outside, tests, 0.05, alternative="greater").pvalue
    print(f"{outside} of {tests} outside the 95 % prediction interval (5 % expected by chance: {0.05 * tests:.1f}); "
          f"binomial p = {p_value:.3g}")
    return p_value < 0.01


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--np", type=int, nargs="+", default=[1, 2, 4, 8])
    parser.add_argument("--seed", type=int, default=12345)
    parser.add_argument("--balance-every", type=int, default=1000)
    parser.add_argument("--replicas", type=Path, nargs="+", default=[],
                        help="run directories of the same case on the first --np with other fill seeds")
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
    outlying = replica_test([runs[reference], *args.replicas], {n: runs[n] for n in others}) if args.replicas else False
    rows = compare_runs([Run(runs[reference])], {f"np{n}": [Run(runs[n])] for n in others})
    table = sweep_markdown(rows)
    print(f"\nagainst np {reference}:\n{table}")
    (args.out / "comparison.md").write_text(table)
    write_sweep_csv(rows, args.out / "comparison.csv")
    significant = [r for r in rows if r.difference.significant]
    unresolved = sum(not r.difference.inputs_resolved for r in rows)
    print(f"{len(rows)} comparisons, {len(significant)} significant, {unresolved} with too few independent samples")
    return 1 if significant or outlying else 0


if __name__ == "__main__":
    sys.exit(main())
