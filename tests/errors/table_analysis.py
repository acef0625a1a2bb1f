"""Bad input to the analysis command line (python -m tsg_analysis report | summary | compare | domains)."""
from __future__ import annotations

import json
from pathlib import Path

from badinput import ROOT, BadInput

ENV = {"PYTHONPATH": str(ROOT / "analysis")}
REPORT = ["{python}", "-m", "tsg_analysis", "report"]
RUN = "{tmp}/run"

ZONES = "# index type x_start_m x_end_m free_volume_m3\n1 conveying 0.0 0.01 4.0e-6\n2 kneading 0.01 0.02 4.0e-6\n"
MASSFLOW_HEADER = "# tsg-dem mass flow v1\n# columns: step time sensor_1 sensor_2\n"
MASSFLOW = (MASSFLOW_HEADER
            + "".join(f"{k * 1000} {k * 0.005:.3f} 14.{k % 7} 13.{k % 5}\n" for k in range(1, 41)))
PARAMS = {"case": "periodic", "scale": "demo", "seed": 1, "np": 1, "variables": {}, "rpm": 600.0, "rho_p": 1263.0,
          "d_mean": 0.001, "mesh_dir": "meshes", "zones_file": "zones.txt", "git_commit": "test"}


def run_dir(params: str | None = json.dumps(PARAMS)) -> dict[str, str]:
    """A small run directory: zones, a 0.2 s mass-flow record, params.json (or the text given)."""
    files = {"run/zones.txt": ZONES, "run/massflow.txt": MASSFLOW}
    if params is not None:
        files["run/params.json"] = params
    return files


def _existing_file(tmp: Path) -> None:
    (tmp / "existing.md").write_text("an earlier report the user wants to keep\n")


def _report_md_is_a_directory(tmp: Path) -> None:
    (tmp / "out" / "report.md").mkdir(parents=True)  # unwritable even for root, unlike a chmod
    (tmp / "out" / "report.md" / "notes.txt").write_text("the user's notes\n")


def report(*words: str) -> list[str]:
    return [*REPORT, *words]


CASES: list[BadInput] = [
    BadInput("analysis.report.steady-window-zero", ("--steady-window 0", "not allowed", "> 0"),
             why="a steady-state window of no length averages nothing",
             command=report(RUN, "--out", "{tmp}/out", "--steady-window", "0"), files=run_dir(), env=ENV),
    BadInput("analysis.report.steady-window-negative", ("--steady-window -0.1", "not allowed", "> 0"),
             why="a window length is positive",
             command=report(RUN, "--out", "{tmp}/out", "--steady-window=-0.1"), files=run_dir(), env=ENV),
    BadInput("analysis.report.steady-window-nan", ("--steady-window nan", "not allowed", "finite"),
             why="nan would make every window comparison false and the run 'never steady'",
             command=report(RUN, "--out", "{tmp}/out", "--steady-window", "nan"), files=run_dir(), env=ENV),
    BadInput("analysis.report.steady-window-text", ("--steady-window", "invalid float value", "'one'"),
             why="the window is a number of seconds",
             command=report(RUN, "--out", "{tmp}/out", "--steady-window", "one"), files=run_dir(), env=ENV),
    BadInput("analysis.report.bin-size-zero", ("--bin-size 0", "not allowed", "0 < size"),
             why="cross-section bins of no size cannot hold particles",
             command=report(RUN, "--out", "{tmp}/out", "--bin-size", "0"), files=run_dir(), env=ENV),
    BadInput("analysis.report.bin-size-larger-than-bore", ("--bin-size 0.05", "not allowed", "bore radius"),
             why="one bin larger than the bore radius is no map",
             command=report(RUN, "--out", "{tmp}/out", "--bin-size", "0.05"), files=run_dir(), env=ENV),
    BadInput("analysis.report.steady-tolerance-zero", ("--steady-tolerance 0", "not allowed", "0 < tolerance < 1"),
             why="inlet and outlet never agree exactly: a zero tolerance makes every run unsteady",
             command=report(RUN, "--out", "{tmp}/out", "--steady-tolerance", "0"), files=run_dir(), env=ENV),
    BadInput("analysis.report.steady-tolerance-above-one", ("--steady-tolerance 1.5", "not allowed"),
             why="a relative difference above 100 % accepts an empty outlet as steady",
             command=report(RUN, "--out", "{tmp}/out", "--steady-tolerance", "1.5"), files=run_dir(), env=ENV),
    BadInput("analysis.report.density-negative", ("--density -1263", "not allowed", "kg/m^3"),
             why="particle masses from a negative density would reverse the mass flow",
             command=report(RUN, "--out", "{tmp}/out", "--density=-1263"), files=run_dir(), env=ENV),
    BadInput("analysis.report.out-is-existing-file", ("--out", "existing.md", "is an existing file"),
             why="writing the report directory over a file would destroy it",
             command=report(RUN, "--out", "{tmp}/existing.md"), files=run_dir(), prepare=_existing_file,
             intact=("existing.md",), env=ENV),
    BadInput("analysis.report.out-under-a-file", ("--out", "cannot create the directory"),
             why="the report directory cannot be created inside a file",
             command=report(RUN, "--out", "{tmp}/existing.md/report"), files=run_dir(), prepare=_existing_file,
             intact=("existing.md",), env=ENV),
    BadInput("analysis.report.out-is-the-run-dir", ("--out", "is a run directory"),
             why="report files (massflow.csv, summary.json ...) would mix with the run's own outputs",
             command=report(RUN, "--out", RUN), files=run_dir(), intact=("run/massflow.txt", "run/zones.txt"),
             env=ENV),
    BadInput("analysis.report.run-dir-missing", ("run_dir", "{tmp}/nowhere", "no such directory"),
             why="a misspelt run directory must not give an empty report",
             command=report("{tmp}/nowhere", "--out", "{tmp}/out"), env=ENV),
    BadInput("analysis.report.run-dir-is-a-file", ("run_dir", "is a file, not a run directory"),
             why="a run is a directory of outputs",
             command=report("{tmp}/run/zones.txt", "--out", "{tmp}/out"), files=run_dir(), env=ENV),
    BadInput("analysis.report.no-run-dir", ("required", "run_dir"),
             why="there is nothing to report on",
             command=report("--out", "{tmp}/out"), env=ENV),
    BadInput("analysis.report.labels-count", ("--labels", "2 labels for 1 run directories"),
             why="each run needs exactly one label",
             command=report(RUN, "--out", "{tmp}/out", "--labels", "a,b"), files=run_dir(), env=ENV),
    BadInput("analysis.report.labels-duplicate", ("--labels", "non-empty and distinct"),
             why="two runs with one label overwrite each other's figures",
             command=report(RUN, RUN, "--out", "{tmp}/out", "--labels", "a,a"), files=run_dir(), env=ENV),
    BadInput("analysis.report.screw-rpm-removed", ("unrecognized arguments", "--screw-rpm"),
             why="the screw speed is the run's own (params.json / TSG-PARAMETERS), never a command-line default",
             command=report(RUN, "--out", "{tmp}/out", "--screw-rpm", "450"), files=run_dir(), env=ENV),
    BadInput("analysis.unknown-command", ("invalid choice", "'plot'"),
             why="only report, summary, compare and domains exist",
             command=["{python}", "-m", "tsg_analysis", "plot", RUN], files=run_dir(), env=ENV),
    BadInput("analysis.report.params-json-broken", ("params.json: line 1", "not valid JSON", "rpm is unknown",
                                                    "--steady-window"),
             why="a damaged parameter record is reported, not replaced by defaults (the rest of the report is written)",
             command=report(RUN, "--out", "{tmp}/out"), files=run_dir('{"rpm": 600, '), accepted=True, env=ENV),
    BadInput("analysis.report.params-rpm-zero", ("params.json: rpm = 0.0 is not allowed", "> 0"),
             why="a screw speed of 0 has no revolution to define the steady-state window",
             command=report(RUN, "--out", "{tmp}/out"), files=run_dir(json.dumps({**PARAMS, "rpm": 0.0})),
             accepted=True, env=ENV),
    BadInput("analysis.report.params-missing-everywhere", ("no params.json and no TSG-PARAMETERS line",
                                                           "rpm is unknown"),
             why="without the run's own rpm the analysis would have to assume one",
             command=report(RUN, "--out", "{tmp}/out"),
             files={**run_dir(None), "run/log.lammps": "LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0)\n"},
             accepted=True, env=ENV),
    BadInput("analysis.report.massflow-header-only", ("massflow.txt", "only its header, no mass-flow rows",
                                                      "not produced: steady state"),
             why="a run stopped before its first mass-flow output: the report says which file lacks what, "
                 "and writes the parts that do not need it",
             command=report(RUN, "--out", "{tmp}/out", "--no-snapshot"),
             files={**run_dir(), "run/massflow.txt": MASSFLOW_HEADER},
             accepted=True, env=ENV),
    BadInput("analysis.report.output-file-not-writable", ("{tmp}/out/report.md", "Is a directory"),
             why="a report file that cannot be written must say which, not end in a traceback",
             command=report(RUN, "--out", "{tmp}/out", "--no-snapshot"), files=run_dir(),
             prepare=_report_md_is_a_directory, intact=("out/report.md/notes.txt",), env=ENV),
    BadInput("analysis.summary.run-dir-missing", ("run_dir", "{tmp}/nowhere", "no such directory"),
             why="a misspelt run directory",
             command=["{python}", "-m", "tsg_analysis", "summary", "{tmp}/nowhere"], env=ENV),
    BadInput("analysis.summary.zones-missing", ("zones.txt", "file not found"),
             why="the elements of every per-element number come from zones.txt",
             command=["{python}", "-m", "tsg_analysis", "summary", RUN],
             files={"run/massflow.txt": MASSFLOW}, env=ENV),
    BadInput("analysis.compare.csv-is-a-directory", ("--csv", "is a directory"),
             why="the table would not be written where the user looks for it",
             command=["{python}", "-m", "tsg_analysis", "compare", RUN, RUN, "--csv", "{tmp}/run"],
             files=run_dir(), env=ENV),
    BadInput("analysis.compare.start", ("--start later is not allowed", "a time in s >= 0, or 'auto'"),
             why="a window must start at a time in the run",
             command=["{python}", "-m", "tsg_analysis", "compare", RUN, RUN, "--start", "later"],
             files=run_dir(), env=ENV),
    BadInput("analysis.compare.end", ("--end soon is not allowed", "a time in s >= 0"),
             why="a window must end at a time in the run",
             command=["{python}", "-m", "tsg_analysis", "compare", RUN, RUN, "--end", "soon"],
             files=run_dir(), env=ENV),
    BadInput("analysis.compare.end-before-start", ("--end 0.5", "must be later than the window's start, 1 s"),
             why="an empty window has no numbers",
             command=["{python}", "-m", "tsg_analysis", "compare", RUN, RUN, "--start", "1", "--end", "0.5"],
             files=run_dir(), env=ENV),
    BadInput("analysis.domains.start", ("--full-start -0.5 is not allowed", "a time in s >= 0, or 'auto'"),
             why="a steady window cannot start before the run",
             command=["{python}", "-m", "tsg_analysis", "domains", RUN, "--full-start", "-0.5", "--periodic-zones",
                      "{tmp}/run/zones.txt"], files=run_dir(), env=ENV),
    BadInput("analysis.domains.nothing-to-do", ("give --periodic a,b,c", "or --periodic-zones FILE"),
             why="without periodic runs or their zones there is nothing to align the full run with",
             command=["{python}", "-m", "tsg_analysis", "domains", RUN, "--full-start", "1"], files=run_dir(), env=ENV),
    BadInput("analysis.domains.no-out", ("give --out DIR",), why="the table and figure need a place",
             command=["{python}", "-m", "tsg_analysis", "domains", RUN, "--full-start", "1", "--periodic", RUN],
             files=run_dir(), env=ENV),
]
