#!/usr/bin/env python3
"""Regenerates the time and speed figures that README.md and docs/performance.md publish, with the
machine, the commit, the command and the spread over repeats; writes docs/measured/*.json and
docs/measured.md (which the README and docs/performance.md link to instead of typed-in numbers).

    .venv/bin/python scripts/measure-figures.py --baseline-lmp LMP | --baseline-commit b9673fc
        [--sections demo paper screws main-job tests] [--repeat 3] [--work DIR] [--render-only]

Sections (each a benchmark script of benchmarks/, run as a subprocess; its JSON lands in
docs/measured/):
- demo: the periodic demo case (3 457 particles of 1 mm, 4 um meshes) from its kept steady state
  (t = 1.5 s), ms/step on 1 and 2 ranks, this build against the baseline lmp side by side
  (interleaved in each repeat): "not slower anywhere" (benchmarks/paper_cost.py --scale demo).
- paper: the same for the paper-scale periodic case (63 320 particles of 400 um, 1 um meshes):
  core-seconds per step, particle-steps per core-second, core-hours per simulated second
  (benchmarks/paper_cost.py --scale paper).
- screws: the README's screw table, stock against corotating screws at 20, 5, 1 um
  (benchmarks/corotating_screws.py; its printed output is kept).
- main-job: the README's main-job figure: `scripts/main-job.sh` (three fills from kept states) as the
  README runs it, wall time and ms/step, --repeat times.
- tests: the README's test-suite figure: `./tsg test` as CI runs it, on a fresh clone of the
  committed HEAD under --work (its own .venv, build, meshes and prepared inputs; the compiler cache
  off unless --warm-compiler-cache), set-up and tests timed apart, once. It also checks the commit:
  the section fails when a test fails.
- scaling: strong scaling from the same restarts (benchmarks/scaling.py; --scaling-np, default 1 2).
- memory: peak memory per rank of the meshes (benchmarks/memory.py; not a time, independent of load).
The baseline is main when the paper-scale speed target was set (b9673fc): give it
(--baseline-lmp) or let the script build it from a commit (--baseline-commit: the commit's files
(git archive) and a build directory under --work, ccache used when present).
Absolute times depend on the machine and its load; the load average is recorded before and after
each section. Ratios come from runs interleaved in one invocation.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MEASURED = ROOT / "docs" / "measured"
DEFAULT_BASELINE_COMMIT = "b9673fc"   # main when the paper-scale speed target was set (its baseline)


def machine() -> dict[str, object]:
    model = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                  if line.startswith("model name")), "unknown CPU")
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    return {"cpu": model, "cores": os.cpu_count(), "host": platform.node(), "load_average": os.getloadavg(),
            "commit": commit + (" (uncommitted changes)" if dirty else ""),
            "utc": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}


def build_baseline(commit: str, work: Path) -> Path:
    """lmp of `commit`: its files and a build directory under work (reused when present)."""
    tree, build = work / f"baseline-{commit}", work / f"baseline-{commit}-build"
    lmp = build / "lmp"
    if lmp.exists():
        return lmp
    if not tree.exists():   # the commit's files (git archive: no worktree registered in the repository)
        tree.mkdir(parents=True)
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", commit], check=True, capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(tree)], input=archive, check=True)
    liggghts = Path.home() / ".cache" / "tsg-dem" / "LIGGGHTS-PUBLIC-3.8.0"
    subprocess.run(["cmake", "-S", str(tree), "-B", str(build), f"-DLIGGGHTS_SOURCE_DIR={liggghts}"], check=True,
                   stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", str(build), "-j", str(os.cpu_count() or 2), "--target", "lmp"], check=True,
                   stdout=subprocess.DEVNULL)
    return lmp


def run_section(name: str, command: list[str], log: Path) -> dict[str, object]:
    print(f"[{name}] {' '.join(shlex.quote(str(a)) for a in command)}", flush=True)
    before = machine()
    start = time.perf_counter()
    with log.open("w") as out:
        done = subprocess.run([str(a) for a in command], cwd=ROOT, stdout=out, stderr=subprocess.STDOUT)
    after = machine()
    if done.returncode != 0:
        raise SystemExit(f"[{name}] failed (exit {done.returncode}): see {log}")
    return {"section": name, "command": [str(a) for a in command], "machine_before": before, "machine_after": after,
            "wall_s": time.perf_counter() - start, "log": str(log)}


def main_job(repeat: int, work: Path, lmp: str) -> dict[str, object]:
    """The README's main job as `./tsg run` runs it (scripts/main-job.sh: three fills from their kept
    states, side by side), wall time and each fill's lmp time and ms/step."""
    runs = []
    build_dir = Path(lmp).resolve().parent
    command = [str(ROOT / "scripts" / "main-job.sh"), str(build_dir)]
    for k in range(repeat):
        out = work / f"main-job-{k}"
        start = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, env=dict(os.environ, TSG_MAIN_OUT=str(out)))
        wall = time.perf_counter() - start
        if done.returncode != 0:
            raise SystemExit(f"[main-job] failed: {done.stdout[-1500:]} {done.stderr[-1500:]}")
        fills = [{"lmp_s": float(m.group(1)), "steps": int(m.group(2)), "ms_per_step": float(m.group(3))}
                 for m in re.finditer(r"\[run\] done in (\S+) s \((\d+) steps, (\S+) ms/step\)", done.stdout)]
        runs.append({"wall_s": wall, "lmp_s": max(f["lmp_s"] for f in fills), "steps": fills[0]["steps"],
                     "ms_per_step": statistics.median(f["ms_per_step"] for f in fills), "fills": len(fills)})
        print(f"[main-job] #{k}: {wall:.0f} s in all, {len(fills)} fills side by side, lmp {runs[-1]['lmp_s']:.0f} s, "
              f"{runs[-1]['ms_per_step']:.3g} ms/step each", flush=True)
    return {"command": ["scripts/main-job.sh", "BUILD_DIR"], "runs": runs}


def test_suite(work: Path, warm_compiler_cache: bool) -> dict[str, object]:
    """`./tsg test` as .ci/run runs it, on a fresh clone of HEAD: the set-up (what a fresh clone lacks:
    .venv, the lmp build, meshes, prepared inputs) and ctest timed apart from the output's step lines."""
    clone = work / "fresh-clone"
    shutil.rmtree(clone, ignore_errors=True)
    subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
    commit = subprocess.run(["git", "-C", str(clone), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True, check=True).stdout.strip()
    env = dict(os.environ)
    if not warm_compiler_cache:
        env["CCACHE_DISABLE"] = "1"   # a fresh machine has no compiler cache
    cached = {"liggghts_source": (Path.home() / ".cache" / "tsg-dem").is_dir(),
              "pip_cache": (Path.home() / ".cache" / "pip").is_dir(), "compiler_cache": warm_compiler_cache}
    log = work / "tests.log"
    start = time.perf_counter()
    marks: dict[str, float] = {}
    with log.open("w") as out:
        proc = subprocess.Popen(["./tsg", "test"], cwd=clone, env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True)
        assert proc.stdout is not None
        for line in proc.stdout:
            out.write(line)
            step = re.match(r"==> \[(setup|test)\] (.*)", line.strip())
            if step:
                marks.setdefault(step.group(2), time.perf_counter() - start)
        rc = proc.wait()
    wall = time.perf_counter() - start
    text = log.read_text()
    summary = re.search(r"(\d+)% tests passed, (\d+) tests failed out of (\d+)", text)
    ctest = re.search(r"Total Test time \(real\) =\s*([\d.]+) sec", text)
    if rc != 0 or not summary or not ctest:
        raise SystemExit(f"[tests] ./tsg test failed (exit {rc}) on the fresh clone {clone}: see {log}")
    setup_s = next((t for name, t in marks.items() if name.startswith("ctest")), wall)
    steps = sorted(marks.items(), key=lambda item: item[1])
    step_s = {name: (steps[k + 1][1] if k + 1 < len(steps) else wall) - t for k, (name, t) in enumerate(steps)}
    print(f"[tests] {wall:.0f} s in all: set-up {setup_s:.0f} s, ctest {float(ctest.group(1)):.0f} s, "
          f"{summary.group(3)} tests, {summary.group(2)} failed", flush=True)
    return {"command": ["git clone REPO CLONE", "cd CLONE", "./tsg test"], "commit": commit, "cached": cached,
            "wall_s": wall, "setup_s": setup_s, "ctest_s": float(ctest.group(1)), "tests": int(summary.group(3)),
            "failed": int(summary.group(2)), "setup_steps_s": step_s, "log": str(log)}


def spread(values: list[float]) -> str:
    if len(values) == 1:
        return f"{values[0]:.3g} (one run)"
    return f"{statistics.median(values):.3g} ({min(values):.3g}–{max(values):.3g}, {len(values)} runs)"


def runs(n: int) -> str:
    return "one run" if n == 1 else f"{n} runs"


def collected_note(data: dict[str, object], log: Path) -> list[str]:
    """For runs collected from an interrupted invocation: where its own command and machine lines are."""
    if not data.get("collected"):
        return []
    heads = [line for line in log.read_text().splitlines() if line.startswith(("command:", "machine"))] if log.exists() else []
    return [f"Collected (`--collect`) from the runs of interrupted invocations, whose own output is in "
            f"`docs/measured/{log.name}`; the machine line above is the time of collecting. Their headers:", "",
            *[f"    {line}" for line in heads], ""]


def load(m: dict[str, object]) -> str:
    values = m["load_average"]
    assert isinstance(values, (list, tuple))
    return "/".join(f"{v:.1f}" for v in values)


def machine_line(meta: dict[str, object], commit: str | None = None) -> list[str]:
    """The machine, commit, times and load of a section run by this script (index.json), if recorded."""
    if not meta:
        return []
    before, after = meta["machine_before"], meta["machine_after"]
    assert isinstance(before, dict) and isinstance(after, dict)
    return [f"{before['cpu']}, {before['cores']} cores, commit {commit or before['commit']}, {before['utc']} to "
            f"{after['utc']}; load average {load(before)} before, {load(after)} after.", ""]


def render() -> str:
    """docs/measured.md from the JSON files present in docs/measured/."""
    lines = ["# Measured figures", "",
             "Written by `scripts/measure-figures.py` from `docs/measured/*.json`; do not edit by hand. Each",
             "section gives the machine (CPU model, cores, load average as 1/5/15-minute means before and after),",
             "the commit, the command and the spread over repeats: median (min–max, runs). Wall-clock numbers",
             "depend on the machine and its load; ratios come from runs interleaved in one invocation.", ""]
    index = json.loads((MEASURED / "index.json").read_text()) if (MEASURED / "index.json").exists() else {}
    for name, title in (("demo", "Periodic demo case from a restart in motion: this build against the baseline"),
                        ("paper", "Paper-scale periodic case from a restart in motion: this build against the baseline")):
        path = MEASURED / f"{name}_cost.json"
        if not path.exists():
            continue
        data = json.loads(path.read_text())
        meta = index.get(name, {})
        lines += [f"## {title}", ""]
        if meta:
            before, after = meta["machine_before"], meta["machine_after"]
            lines += [f"{before['cpu']}, {before['cores']} cores ({before['host']}), commit {before['commit']}, "
                      f"{before['utc']} to {after['utc']}; load average {load(before)} before, {load(after)} after.", ""]
        else:
            lines += [f"Machine: {data['machine_at_start']}; at the end: {data['machine_at_end']}.", ""]
        lines += collected_note(data, MEASURED / f"{name}_cost.log")
        lines += ["    " + " ".join(shlex.quote(a) for a in data["command"]), "",
                  f"Baseline lmp: `{data['lmp']['baseline']}`; this: `{data['lmp']['this']}`. {data['steps']} steps "
                  f"per run, {data['repeat']} repeats, time step {data['time_step_s']:.4g} s.", ""]
        if data.get("case_variables"):
            lines += ["Case variables of each: " + "; ".join(
                f"{label} {' '.join(f'{k}={v}' for k, v in values.items()) or '(the case defaults)'}"
                for label, values in data["case_variables"].items()) + ".", ""]
        state = [r for r in data["runs"] if r.get("neighbour_builds", -1) >= 0]
        if state:
            # this build's runs: a baseline that predates the time entry in restart files starts its clock at 0
            times = sorted({round(r["time_s"], 6) for r in state
                            if r["label"] == "this" and r.get("time_s", float("nan")) == r.get("time_s")})
            at = f"at t = {', '.join(f'{t:g}' for t in times)} s of simulated time, " if times else ""
            lines += [f"State of the runs: {at}{spread([r['neighbours_per_particle'] for r in state])} pair neighbours "
                      f"per particle, {spread([1e3 * r['neighbour_builds'] / r['steps'] for r in state])} "
                      "neighbour-list builds per 1 000 steps.", ""]
        lines += [
                  "| ranks | baseline ms/step | this ms/step | baseline / this (core-s per step, per repeat) | "
                  "this: M particle-steps per core-s | this: core-h per simulated s | this: fix ms/step |",
                  "|---|---|---|---|---|---|---|"]
        for row in data["summary"]:
            mine = [r for r in data["runs"] if r["label"] == "this" and r["np"] == row["np"]]
            base = [r for r in data["runs"] if r["label"] == "baseline" and r["np"] == row["np"]]
            ratio = [b["core_ms_per_step"] / m["core_ms_per_step"] for b, m in zip(base, mine)]
            lines.append(f"| {row['np']} | {spread([r['ms_per_step'] for r in base])} | "
                         f"{spread([r['ms_per_step'] for r in mine])} | {spread(ratio)} | "
                         f"{spread([r['particle_steps_per_core_s'] / 1e6 for r in mine])} | "
                         f"{spread([r['core_hours_per_sim_s'] for r in mine])} | "
                         f"{spread([r['fix_ms_per_step'] for r in mine])} |")
        lines.append("")
    if (MEASURED / "main_job.json").exists():
        data = json.loads((MEASURED / "main_job.json").read_text())
        lines += ["## Main job: the periodic demo case as the README runs it", "",
                  *machine_line(index.get("main-job", {}))]
        lines += ["    " + " ".join(shlex.quote(a) for a in data["command"]), "",
                  f"- wall time after the set-up (the fills, the summary and the report): "
                  f"{spread([r['wall_s'] for r in data['runs']])} s",
                  f"- lmp run: {spread([r['lmp_s'] for r in data['runs']])} s (the slowest of "
                  f"{data['runs'][0].get('fills', 1)} fills side by side), {spread([r['ms_per_step'] for r in data['runs']])} "
                  f"ms/step per fill ({data['runs'][0]['steps']} steps each)", ""]
    if (MEASURED / "test_suite.json").exists():
        data = json.loads((MEASURED / "test_suite.json").read_text())
        lines += ["## Test suite: the README's test command on a fresh clone", "",
                  *machine_line(index.get("tests", {}), data["commit"])]
        cached = data["cached"]
        lines += ["    " + "; ".join(data["command"]), "",
                  f"- in all: {data['wall_s'] / 60:.1f} min ({data['tests']} tests, {data['failed']} failed)",
                  f"- set-up of the fresh clone: {data['setup_s'] / 60:.1f} min ("
                  + ", ".join(f"{name}: {t:.0f} s" for name, t in data["setup_steps_s"].items()
                              if not name.startswith(("ctest", "ALL", "TESTS"))) + ")",
                  f"- tests (ctest): {data['ctest_s'] / 60:.1f} min",
                  f"- present before: the Debian packages; the upstream LIGGGHTS source "
                  f"{'cached' if cached['liggghts_source'] else 'not cached'}; pip's download cache "
                  f"{'present' if cached['pip_cache'] else 'absent'}; the compiler cache "
                  f"{'on' if cached['compiler_cache'] else 'off (CCACHE_DISABLE=1): every file compiled'}", ""]
    if (MEASURED / "screws.txt").exists():
        meta = index.get("screws", {})
        lines += ["## Screws: stock against corotating (benchmarks/corotating_screws.py, as printed)", ""]
        if meta:
            before = meta["machine_before"]
            lines += [f"{before['cpu']}, {before['cores']} cores, commit {before['commit']}, {before['utc']}; "
                      f"load average {load(before)} before, {load(meta['machine_after'])} after.", "",
                      "    " + " ".join(shlex.quote(a) for a in meta["command"]), ""]
        lines += ["```", (MEASURED / "screws.txt").read_text().strip(), "```", ""]
    if (MEASURED / "scaling.json").exists():
        data = json.loads((MEASURED / "scaling.json").read_text())
        lines += ["## Strong scaling from a restart in motion (benchmarks/scaling.py)", "",
                  f"Machine: {data['machine_at_start']}; at the end: {data['machine_at_end']}.", "",
                  "    " + " ".join(shlex.quote(a) for a in data["command"]), "",
                  "| scale | particles | steps | ranks | ms/step | speed-up | efficiency |", "|---|---|---|---|---|---|---|"]
        for block in data["scales"]:
            for row in block["rows"]:
                t = row["ms_per_step"]
                lines.append(f"| {block['scale']} | {block['atoms']} | {block['steps']} | {row['np']} | "
                             f"{t['median']:.3g} ({t['min']:.3g}–{t['max']:.3g}, {runs(t['n'])}) | "
                             f"{row['speed_up']:.2f} | {row['efficiency']:.2f} |")
        lines.append("")
    if (MEASURED / "memory.json").exists():
        data = json.loads((MEASURED / "memory.json").read_text())
        lines += ["## Peak memory per rank (benchmarks/memory.py)", "",
                  f"Machine: {data['machine']}.", "", *collected_note(data, MEASURED / "memory.log"),
                  "    " + " ".join(shlex.quote(a) for a in data["command"]), "",
                  "VmHWM of each rank (/usr/bin/time), one particle, `processors N 1 1`; LIGGGHTS' own report "
                  "(\"Memory usage per processor\"); the corotating fix's triangle storage from the layout.", "",
                  "| meshes | triangles | variant | ranks | MB per rank (max) | MB per rank (mean) | MB all ranks | "
                  "LIGGGHTS report MB | fix triangles MB (layout) |", "|---|---|---|---|---|---|---|---|---|"]
        for r in data["runs"]:
            lines.append(f"| {r['mesh']} | {sum(r['triangles'].values())} | {r['variant']} | {r['np']} | "
                         f"{r['hwm_mb_max']:.0f} | {r['hwm_mb_mean']:.0f} | {r['hwm_mb_node']:.0f} | "
                         f"{r['liggghts_report_mb']:.0f} | {r['fix_copy_mb']:.0f} |")
        lines.append("")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    baseline = parser.add_mutually_exclusive_group()
    baseline.add_argument("--baseline-lmp", help="the baseline lmp (default: built from --baseline-commit)")
    baseline.add_argument("--baseline-commit", default=DEFAULT_BASELINE_COMMIT,
                          help=f"build the baseline lmp from this commit (default {DEFAULT_BASELINE_COMMIT})")
    parser.add_argument("--lmp", default=os.environ.get("TSG_LMP", str(ROOT / "build" / "lmp")))
    parser.add_argument("--sections", nargs="+", choices=["demo", "paper", "screws", "main-job", "tests", "scaling", "memory"],
                        default=["demo", "paper", "screws", "main-job"])
    parser.add_argument("--warm-compiler-cache", action="store_true",
                        help="tests: keep ccache on (as CI here) instead of compiling every file as a fresh machine")
    parser.add_argument("--scaling-np", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--work", type=Path, default=Path("/tmp/measure-figures"),
                        help="prepared fills, restarts, the baseline build (reused between calls)")
    parser.add_argument("--paper-restart", type=Path, default=None, help="a paper-scale restart in motion to reuse")
    parser.add_argument("--render-only", action="store_true", help="only rewrite docs/measured.md from the JSON")
    args = parser.parse_args(argv)
    MEASURED.mkdir(parents=True, exist_ok=True)
    if not args.render_only:
        args.work.mkdir(parents=True, exist_ok=True)
        index_path = MEASURED / "index.json"
        index = json.loads(index_path.read_text()) if index_path.exists() else {}
        needs_baseline = {"demo", "paper"} & set(args.sections)
        base = (args.baseline_lmp or str(build_baseline(args.baseline_commit, args.work))) if needs_baseline else ""
        bench = [sys.executable, ROOT / "benchmarks" / "paper_cost.py", "--baseline-lmp", base, "--lmp", args.lmp,
                 "--np", "1", "2", "--repeat", str(args.repeat), "--work", args.work,
                 # the default baseline (b9673fc) predates the time entry in restart headers: both read a copy without it
                 "--restart-without-time"]
        for section in args.sections:
            if section == "demo":
                command = bench + ["--scale", "demo", "--steps", "1000", "--thermo-every", "500",
                                   "--json", MEASURED / "demo_cost.json"]
            elif section == "paper":
                command = bench + ["--scale", "paper", "--steps", "300", "--thermo-every", "100",
                                   "--json", MEASURED / "paper_cost.json"]
                if args.paper_restart:
                    command += ["--restart", args.paper_restart]
            elif section == "screws":
                command = [sys.executable, ROOT / "benchmarks" / "corotating_screws.py", "--np", "1"]
            elif section == "scaling":
                command = [sys.executable, ROOT / "benchmarks" / "scaling.py", "--lmp", args.lmp, "--np",
                           *map(str, args.scaling_np), "--repeat", str(args.repeat), "--work", args.work,
                           "--json", MEASURED / "scaling.json"]
            elif section == "memory":
                command = [sys.executable, ROOT / "benchmarks" / "memory.py", "--lmp", args.lmp, "--variant-np", "1", "4",
                           "--work", args.work / "memory", "--json", MEASURED / "memory.json"]
            elif section == "tests":
                before = machine()
                result = test_suite(args.work, args.warm_compiler_cache)
                (MEASURED / "test_suite.json").write_text(json.dumps(result, indent=1) + "\n")
                index[section] = {"section": section, "command": result["command"], "machine_before": before,
                                  "machine_after": machine()}
                index_path.write_text(json.dumps(index, indent=1) + "\n")
                continue
            else:
                before = machine()
                result = main_job(args.repeat, args.work, args.lmp)
                (MEASURED / "main_job.json").write_text(json.dumps(result, indent=1) + "\n")
                index[section] = {"section": section, "command": result["command"], "machine_before": before,
                                  "machine_after": machine()}
                index_path.write_text(json.dumps(index, indent=1) + "\n")
                continue
            index[section] = run_section(section, command, args.work / f"{section}.log")
            if section == "screws":
                (MEASURED / "screws.txt").write_text(Path(index[section]["log"]).read_text())
            index_path.write_text(json.dumps(index, indent=1) + "\n")
    (ROOT / "docs" / "measured.md").write_text(render() + "\n")
    print(f"wrote {ROOT / 'docs' / 'measured.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
