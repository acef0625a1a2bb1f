"""Progress of a running case, read from its log.lammps as LIGGGHTS writes it.

    with subprocess.Popen(command, cwd=out, ...) as proc:
        status = follow(proc, out / "log.lammps", total_time=0.3)   # a line every 10 s until lmp ends

    with Heartbeat("placing the particles"):                       # a line every 10 s while it works
        fill(...)

    python -m tsg_cases.progress follow RUN_DIR [--total-time S]   # follow a run started elsewhere
    python -m tsg_cases.progress wait [--every S] LABEL -- COMMAND ...   # COMMAND with a heartbeat line

Each line: simulated time and percent of the planned time, ETA, step, particles, escaped particles,
fast events (particles released from a squeeze faster than guard_fast_speed, counted: `fast`)
and the overlap monitors of cases/include/thermo.in (largest pair overlap/radius `pp_max`, largest
wall overlap/radius against screw 1, screw 2 and the barrel `pg_scr1/pg_scr2/pg_bar`), and how old
the last thermo row is: LIGGGHTS writes a row every thermo_every steps only, so at the paper scale
the numbers may be minutes old while the line itself comes every `every` seconds. The ETA is the
remaining simulated time over the rate measured since the first row this follower saw.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, TextIO

DEFAULT_EVERY = float(os.environ.get("TSG_PROGRESS_EVERY", "10"))   # seconds between lines
MONITORS = ("pp_max", "pg_scr1", "pg_scr2", "pg_bar")                 # thermo.in's overlap columns


@dataclass
class LogFollower:
    """The latest thermo row of a growing LIGGGHTS log, read incrementally (complete lines only)."""
    path: Path
    offset: int = 0
    columns: list[str] | None = None
    latest: dict[str, float] | None = None
    events: list[str] = field(default_factory=list)   # TSG-* and ERROR lines, in order
    _partial: bytes = b""

    def poll(self) -> bool:
        """Read what was appended since the last call; True when a new thermo row arrived."""
        try:
            with open(self.path, "rb") as log:
                size = log.seek(0, os.SEEK_END)
                if size < self.offset:          # the log was started again (LIGGGHTS `log` command)
                    self.offset, self._partial, self.columns = 0, b"", None
                log.seek(self.offset)
                chunk = log.read()
        except FileNotFoundError:
            return False
        self.offset += len(chunk)
        lines = (self._partial + chunk).split(b"\n")
        self._partial = lines.pop()             # an incomplete last line waits for its end
        fresh = False
        for raw in lines:
            fresh |= self._line(raw.decode("utf-8", errors="replace"))
        return fresh

    def _line(self, line: str) -> bool:
        words = line.split()
        if not words:
            return False
        if words[0] == "Step" and len(words) > 1:
            self.columns = words
            return False
        if words[0].startswith("TSG-") or words[0].startswith("ERROR"):
            self.events.append(line.strip())
            return False
        if line.startswith("Loop time of"):
            self.columns = None
            return False
        if self.columns is None or len(words) != len(self.columns):
            return False
        try:
            values = [float(w) for w in words]
        except ValueError:
            return False
        self.latest = dict(zip(self.columns, values))
        return True


def duration(seconds: float) -> str:
    seconds = max(0, round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60:02d} s"
    if seconds < 48 * 3600:
        return f"{seconds // 3600} h {seconds % 3600 // 60:02d} min"
    return f"{seconds / 86400:.1f} days"


@dataclass
class Progress:
    """Turns thermo rows seen at wall-clock times into progress lines."""
    total_time: float | None        # planned simulated time, s (None: unknown)
    label: str = "progress"
    first: tuple[float, float] | None = None   # (wall, simulated time) of the first row seen
    last: tuple[float, float] | None = None    # (wall, simulated time) of the newest row

    def observe(self, row: dict[str, float], wall: float) -> None:
        point = (wall, row["Time"])
        if self.first is None:
            self.first = point
        self.last = point

    def rate(self) -> float | None:
        """Simulated seconds per wall second since the first row seen (None before two rows)."""
        if self.first is None or self.last is None or self.last[0] <= self.first[0]:
            return None
        advance = self.last[1] - self.first[1]
        return advance / (self.last[0] - self.first[0]) if advance > 0 else None

    def eta(self, wall: float) -> float | None:
        """Wall seconds left: the remaining simulated time at the measured rate, counted from the
        newest row (the time since it was written is already spent)."""
        rate = self.rate()
        if rate is None or self.total_time is None or self.last is None:
            return None
        return max(0.0, (self.total_time - self.last[1]) / rate - (wall - self.last[0]))

    def line(self, row: dict[str, float] | None, wall: float, started: float) -> str:
        if row is None or self.last is None:
            return f"[{self.label}] setting up (meshes, particles): {duration(wall - started)} since the start"
        t = row["Time"]
        if self.total_time:
            share = f"t = {t:.4g} of {self.total_time:.4g} s ({100 * t / self.total_time:.1f} %)"
        else:
            share = f"t = {t:.4g} s"
        eta = self.eta(wall)
        parts = [share, f"ETA {duration(eta)}" if eta is not None else "ETA after the next row",
                 f"step {int(row['Step'])}", f"{int(row['Atoms'])} particles"]
        if "escaped" in row:
            parts.append(f"escaped {int(row['escaped'])}")
        if "fast" in row:
            parts.append(f"fast events {int(row['fast'])}")
        if all(name in row for name in MONITORS):
            parts.append(f"overlap/R pair {row['pp_max']:.3g}, walls {row['pg_scr1']:.3g}/{row['pg_scr2']:.3g}/"
                         f"{row['pg_bar']:.3g} (screw 1/screw 2/barrel)")
        parts.append(f"row {duration(wall - self.last[0])} old")
        return f"[{self.label}] " + ", ".join(parts)


def follow(proc: subprocess.Popen, log: Path, total_time: float | None, every: float = DEFAULT_EVERY,
           out: TextIO = sys.stdout, label: str = "progress", clock: Callable[[], float] = time.monotonic,
           poll_interval: float = 0.5) -> int:
    """Wait for `proc`, printing a progress line every `every` seconds (and one at the end) from
    the log it writes; returns its exit status."""
    follower = LogFollower(Path(log))
    progress = Progress(total_time, label)
    started = next_line = clock()
    next_line += every

    def read() -> None:
        if follower.poll() and follower.latest is not None:
            progress.observe(follower.latest, clock())

    while proc.poll() is None:
        time.sleep(min(poll_interval, every))
        read()
        now = clock()
        if now >= next_line:
            print(progress.line(follower.latest, now, started), file=out, flush=True)
            next_line = now + every
    read()
    print(progress.line(follower.latest, clock(), started) + f" [lmp exited: {proc.returncode}]", file=out, flush=True)
    return int(proc.returncode)


class Heartbeat:
    """A line every `every` seconds while a long step of this process (meshes, fill) works; the
    step itself reports no fraction, so the line gives the time spent and, when known, the time the
    step took when measured (`expected`, e.g. "about 10 min on 2 loaded cores")."""

    def __init__(self, what: str, every: float = DEFAULT_EVERY, out: TextIO = sys.stdout, label: str = "prepare",
                 expected: str | None = None):
        self.what, self.every, self.out, self.label, self.expected = what, every, out, label, expected
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._beat, daemon=True)
        self._started = 0.0

    def _beat(self) -> None:
        while not self._stop.wait(self.every):
            hint = f" (measured: {self.expected})" if self.expected else ""
            print(f"[{self.label}] {self.what}: {duration(time.monotonic() - self._started)} so far{hint}",
                  file=self.out, flush=True)

    def start(self) -> "Heartbeat":
        self._started = time.monotonic()
        print(f"[{self.label}] {self.what} ...", file=self.out, flush=True)
        self._thread.start()
        return self

    def stop(self, state: str = "done") -> None:
        self._stop.set()
        self._thread.join()
        print(f"[{self.label}] {self.what}: {state} in {duration(time.monotonic() - self._started)}",
              file=self.out, flush=True)

    def __enter__(self) -> "Heartbeat":
        return self.start()

    def __exit__(self, kind, value, traceback) -> None:
        self.stop("done" if kind is None else "stopped")


def follow_file(log: Path, total_time: float | None, every: float, out: TextIO = sys.stdout) -> None:
    """Follow a log written by a process started elsewhere until it prints TSG-DONE or an ERROR."""
    follower = LogFollower(Path(log))
    progress = Progress(total_time)
    started = time.monotonic()
    while True:
        if follower.poll() and follower.latest is not None:
            progress.observe(follower.latest, time.monotonic())
        print(progress.line(follower.latest, time.monotonic(), started), file=out, flush=True)
        finished = [e for e in follower.events if e.startswith(("TSG-DONE", "ERROR"))]
        if finished:
            print(f"[progress] {finished[0]}", file=out, flush=True)
            return
        time.sleep(every)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tsg_cases.progress", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    f = sub.add_parser("follow", help="print the progress of a run from its log until it ends")
    f.add_argument("run_dir", type=Path, help="the run's directory (its log.lammps) or the log file")
    f.add_argument("--total-time", type=float, help="planned simulated time, s (for the percent and the ETA)")
    f.add_argument("--every", type=float, default=DEFAULT_EVERY, help="seconds between lines")
    w = sub.add_parser("wait", help="run a command, printing a line every --every seconds until it ends (options before LABEL)")
    w.add_argument("label")
    w.add_argument("--every", type=float, default=DEFAULT_EVERY)
    w.add_argument("--expected", help="how long the step took when measured (printed with each line)")
    w.add_argument("cmd", nargs=argparse.REMAINDER, help="-- COMMAND ...")
    args = parser.parse_args(argv)
    if not args.every > 0:
        print(f"tsg-progress: error: --every {args.every} is not allowed: seconds between lines, > 0", file=sys.stderr)
        return 2
    if args.command == "wait":
        command = args.cmd[1:] if args.cmd[:1] == ["--"] else args.cmd
        if not command:
            print("tsg-progress: error: wait needs a command after --", file=sys.stderr)
            return 2
        with Heartbeat(args.label, args.every, expected=args.expected):
            return subprocess.run(command).returncode
    log = args.run_dir / "log.lammps" if args.run_dir.is_dir() else args.run_dir
    if not log.is_file():
        print(f"tsg-progress: error: {log} does not exist (the run writes it when it starts)", file=sys.stderr)
        return 2
    if args.total_time is not None and not args.total_time > 0:
        print(f"tsg-progress: error: --total-time {args.total_time} is not allowed: simulated seconds, > 0", file=sys.stderr)
        return 2
    try:
        follow_file(log, args.total_time, args.every)
    except KeyboardInterrupt:
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
