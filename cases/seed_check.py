"""Run a granulator case for several fill seeds and check every run for lost, escaped and crushed particles.

    .venv/bin/python cases/seed_check.py [--seeds 1 2 3 4 5] [--out runs/seed-check] [--case periodic]
        [--max-pair-overlap 0.5] [--max-wall-overlap 0.5] [--max-speed V] [any cases/run_case.py option: --scale, --np, -v NAME VALUE, ...]

Each seed runs `cases/run_case.py CASE --seed N --out OUT/seed-N` with the other options passed
through, then its log.lammps is read. Per seed it prints: the largest particle–particle overlap δ/R
(fix check/contact's monitor v_pp_max, R the smaller radius), the largest particle–wall overlap δ/r
against the screws and the barrel (the monitors v_pg_scr1, v_pg_scr2, v_pg_bar of timestep.in),
the largest particle speed (v_speed), the particles lost (fewer atoms than filled, or LIGGGHTS' "Lost
atoms") and escaped (v_escaped), and the wall time. The wall monitor and the speed cover every step;
the pair monitor is sampled at thermo output (every `thermo_every` steps). A seed whose run succeeded
before with the same options (OUT/seed-N/seed-check.json) is reused, so an interrupted check
continues where it stopped. A seed fails when run_case.py fails, a particle is lost
or escaped, or an overlap or the speed exceeds its bound; the exit status is 1 when any seed fails.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


@dataclass
class SeedResult:
    seed: int
    exit_status: int
    pair_overlap: float        # largest particle–particle δ/R; nan when no thermo output
    wall_overlap: float      # largest particle–wall δ/r; nan when the input has no monitor
    speed: float             # largest particle speed, m/s; nan when the input has no monitor
    filled: int
    lost: int
    escaped: int
    wall_time: float
    error: str

    def failures(self, max_pair: float, max_wall: float, max_speed: float = float("inf")) -> list[str]:
        reasons = []
        if self.exit_status != 0:
            reasons.append(f"run_case.py exit {self.exit_status}" + (f" ({self.error})" if self.error else ""))
        if self.lost:
            reasons.append(f"{self.lost} lost")
        if self.escaped:
            reasons.append(f"{self.escaped} escaped")
        if not self.pair_overlap <= max_pair:
            reasons.append(f"pair overlap {self.pair_overlap:.3g} > {max_pair}")
        if self.wall_overlap > max_wall:
            reasons.append(f"wall overlap {self.wall_overlap:.3g} > {max_wall}")
        if self.speed > max_speed:
            reasons.append(f"speed {self.speed:.3g} m/s > {max_speed}")
        return reasons


def thermo_rows(log: str) -> list[tuple[list[str], np.ndarray]]:
    """Thermo blocks as (header words, rows). Columns are taken by position: LIGGGHTS shortens
    headers to 8 characters, so names can repeat."""
    blocks: list[tuple[list[str], np.ndarray]] = []
    header: list[str] | None = None
    rows: list[list[float]] = []
    for line in log.splitlines() + ["Loop time of (end)"]:
        words = line.split()
        if header is None:
            if len(words) > 1 and words[0] == "Step":
                header, rows = words, []
            continue
        if line.startswith("Loop time of"):
            if rows:
                blocks.append((header, np.array(rows)))
            header = None
            continue
        if len(words) == len(header):
            try:
                rows.append([float(w) for w in words])
            except ValueError:
                pass
    return blocks


def read_run(log: str) -> tuple[float, float, float, int, int, int]:
    """From the thermo output of log.lammps: the largest pair δ/R ('pp_max'), the largest wall δ/r
    over the screws and the barrel ('pg_scr1', 'pg_scr2', 'pg_bar'; nan without them), the largest
    speed ('speed'; nan without it), the filled count (atoms in the first row; in a feed case, which
    starts empty, the largest count), the fewest atoms (a feed case: the same), the most escaped."""
    prefixes = ("Atoms", "pp_max", "pg_", "speed", "escaped")
    parts: dict[str, list[np.ndarray]] = {prefix: [] for prefix in prefixes}
    for header, rows in thermo_rows(log):
        for prefix in prefixes:
            hits = [k for k, name in enumerate(header) if name.startswith(prefix)]
            if hits:
                parts[prefix].append(rows[:, hits].max(axis=1))
    column = {prefix: np.concatenate(p) if p else np.zeros(0) for prefix, p in parts.items()}

    def largest(values: np.ndarray) -> float:
        return float(values.max()) if values.size else float("nan")
    atoms = column["Atoms"]
    filled, fewest = (int(atoms[0]), int(atoms.min())) if atoms.size else (0, 0)
    if filled == 0 and atoms.size:
        # a feed case (no particles at step 0): the count grows with the generation and falls at the
        # outlet, so the largest count is reported and losses come from LIGGGHTS' "Lost atoms" check
        # and the escape counter only
        filled = fewest = int(atoms.max())
    escaped = int(column["escaped"].max()) if column["escaped"].size else 0
    return largest(column["pp_max"]), largest(column["pg_"]), largest(column["speed"]), filled, fewest, escaped


def run_seed(seed: int, out: Path, case: str, passthrough: list[str]) -> SeedResult:
    run_dir = out / f"seed-{seed}"
    command = [sys.executable, str(ROOT / "cases" / "run_case.py"), case, "--seed", str(seed),
               "--out", str(run_dir), *passthrough]
    record = run_dir / "seed-check.json"
    finished = json.loads(record.read_text()) if record.is_file() else {}
    if finished.get("command") == command[2:] and finished["exit_status"] == 0:   # reuse: a study resumes
        exit_status, wall_time, error = finished["exit_status"], finished["wall_time"], finished["error"]
    else:
        start = time.perf_counter()
        proc = subprocess.run(command, capture_output=True, text=True)
        wall_time = time.perf_counter() - start
        exit_status = proc.returncode
        error = next((line.strip() for line in reversed((proc.stderr or "").splitlines()) if line.strip()), "")
        run_dir.mkdir(parents=True, exist_ok=True)
        record.write_text(json.dumps({"command": command[2:], "exit_status": exit_status,
                                      "wall_time": wall_time, "error": error}))
    log_file = run_dir / "log.lammps"
    log = log_file.read_text(errors="replace") if log_file.exists() else ""
    screen = run_dir / "screen.txt"
    text = log + (screen.read_text(errors="replace") if screen.exists() else "")
    pair, wall, speed, filled, fewest, escaped = read_run(log)
    lost = filled - fewest if filled else 0
    if "Lost atoms" in text:
        lost = max(lost, 1)
    return SeedResult(seed, exit_status, pair, wall, speed, filled, lost, escaped, wall_time, error)


def table(results: list[SeedResult], max_pair: float, max_wall: float, max_speed: float = float("inf")) -> str:
    def number(value: float) -> str:
        return "n/a" if np.isnan(value) else f"{value:.3f}"
    lines = [f"{'seed':>6} {'particles':>9} {'pair δ/R':>9} {'wall δ/r':>10} {'speed m/s':>9} {'lost':>5} "
             f"{'escaped':>7} {'wall s':>7}  verdict"]
    for r in results:
        reasons = r.failures(max_pair, max_wall, max_speed)
        lines.append(f"{r.seed:>6} {r.filled:>9} {number(r.pair_overlap):>9} {number(r.wall_overlap):>10} "
                     f"{number(r.speed):>9} "
                     f"{r.lost:>5} {r.escaped:>7} {r.wall_time:>7.0f}  {'FAIL: ' + '; '.join(reasons) if reasons else 'ok'}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter,
                                     allow_abbrev=False)
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5], help="fill seeds")
    parser.add_argument("--case", default="periodic", help="case of cases/run_case.py (default periodic)")
    parser.add_argument("--out", type=Path, default=ROOT / "runs" / "seed-check", help="one seed-N directory per seed")
    parser.add_argument("--max-pair-overlap", type=float, default=0.5,
                        help="largest allowed particle-particle δ/R (default 0.5)")
    parser.add_argument("--max-wall-overlap", type=float, default=0.5,
                        help="largest allowed particle-wall δ/r (default 0.5; > 1 means the centre is outside)")
    parser.add_argument("--max-speed", type=float, default=float("inf"),
                        help="largest allowed particle speed, m/s (default: no bound; the run's speed guard stops it)")
    args, passthrough = parser.parse_known_args(argv)
    for name in ("max_pair_overlap", "max_wall_overlap", "max_speed"):
        value = getattr(args, name)
        if not 0.0 < value:
            parser.error(f"--{name.replace('_', '-')} {value} is not allowed: a positive bound")
    if "--seed" in passthrough:
        parser.error("--seed is set per seed by seed_check.py: use --seeds N [N ...]")
    results = []
    for seed in args.seeds:
        print(f"[seed-check] seed {seed} ...", flush=True)
        results.append(run_seed(seed, args.out.resolve(), args.case, passthrough))
        print(table(results[-1:], args.max_pair_overlap, args.max_wall_overlap, args.max_speed).splitlines()[-1],
              flush=True)
    print(table(results, args.max_pair_overlap, args.max_wall_overlap, args.max_speed))
    failed = [r.seed for r in results if r.failures(args.max_pair_overlap, args.max_wall_overlap, args.max_speed)]
    print(f"[seed-check] {len(results) - len(failed)} of {len(results)} seeds passed"
          + (f"; failed: {' '.join(map(str, failed))}" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
