"""Run one lmp input in a directory and print a short summary (the README's main job)."""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

from .liggghts_log import parse_thermo, parse_warnings


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--lmp", required=True, type=Path)
    parser.add_argument("--input", required=True, type=Path)
    parser.add_argument("--workdir", required=True, type=Path)
    args = parser.parse_args(argv)
    args.workdir.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    with open(args.workdir / "screen.txt", "w") as screen:
        proc = subprocess.run([str(args.lmp), "-in", str(args.input.resolve()), "-log", "log.lammps",
                               "-echo", "none"], cwd=args.workdir, stdout=screen, stderr=subprocess.STDOUT)
    wall = time.perf_counter() - start
    log_path = args.workdir / "log.lammps"
    log = log_path.read_text(errors="replace") if log_path.exists() else ""
    if proc.returncode != 0:
        print("\n".join((args.workdir / "screen.txt").read_text().splitlines()[-20:]))
        print(f"[run] lmp failed with exit code {proc.returncode} (log: {log_path})", file=sys.stderr)
        return 1
    thermo = parse_thermo(log)[-1]
    steps = int(thermo["Step"][-1])
    warnings = parse_warnings(log)
    print(f"particles        {int(thermo['Atoms'][-1])}")
    print(f"steps            {steps}")
    print(f"kinetic energy   {thermo['KinEng'][0]:.3e} J -> {thermo['KinEng'][-1]:.3e} J")
    print(f"wall time        {wall:.1f} s ({steps / wall:.0f} steps/s)")
    print(f"warnings         {len(warnings)}" + "".join(f"\n  {w}" for w in warnings))
    print(f"log              {log_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
