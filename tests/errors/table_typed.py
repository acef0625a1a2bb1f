"""Rows of the bad-input campaign for the inputs run as typed (cases/in.tsg_* with their defaults,
docs/cluster.md): a fill or feed file made for other values than the run's stops the run with the
command that makes the right one; cases/prepared.py refuses bad options. The lmp rows use the 5 um
meshes of ./tsg setup and a one-particle fill / two-cube feed, and stop before the first step."""
from __future__ import annotations

import os
from pathlib import Path

from badinput import ROOT, BadInput

BUILD = Path(os.environ.get("TSG_BUILD_DIR", ROOT / "build"))
MESHES = {case: BUILD / "meshes" / f"consigma1-{case}-5um" for case in ("periodic", "nonperiodic", "full")}
PREPARED = ["{python}", "-m", "tsg_cases.prepared"]


def fill(d_mean: float = 4e-4, psd_sigma: float = 0.05, rho_p: float = 1263.0, length: float = 0.0958333333333) -> str:
    return ("create_atoms 1 single 0.01 0.0 0.0 units box\nset atom 1*1 diameter 4e-4 density ${rho_p}\n"
            "variable fill_count equal 1\nvariable d_min equal 4e-4\n"
            f"variable fill_d_mean equal {d_mean}\nvariable fill_psd_sigma equal {psd_sigma}\n"
            f"variable fill_rho_p equal {rho_p}\nvariable fill_domain_length equal {length}\n")


def feed(d_mean: float, length: float, feed_at: str) -> str:
    return ("region feed_1 block 0.05 0.051 -0.001 0.001 0.008 0.009 units box\n"
            "region feed_2 block 0.051 0.052 -0.001 0.001 0.008 0.009 units box\nregion feed union 2 feed_1 feed_2\n"
            "variable feed_volume equal 1e-9\n"
            f"variable feed_d_mean equal {d_mean}\nvariable feed_x_start equal 0.19\nvariable feed_x_end equal 0.22\n"
            f"variable feed_domain_length equal {length}\nvariable feed_at string {feed_at}\n")


def typed(case: str, file_name: str, *variables: str) -> list[str]:
    """The case input with its defaults but for the meshes, the output folder and the prepared file."""
    name = "fill_file" if case == "periodic" else "feed_file"
    return ["{lmp}", "-in", f"{{root}}/cases/in.tsg_{case}", "-echo", "none", "-var", "case_dir", "{root}/cases",
            "-var", "out_dir", "{tmp}", "-var", "mesh_dir", str(MESHES[case]), "-var", name, file_name, *variables]


CASES: list[BadInput] = [
    BadInput("typed.periodic.fill-for-other-d_mean",
             ("fill_file = fill.in was made for d_mean = 0.001", "not for this run with d_mean = 0.0004",
              "python -m tsg_cases.prepared fill", "--d-mean 0.0004 --psd-sigma 0.05 --rho-p 1263", "and run with -var fill_file"),
             why="a fill of other particles would run with sizes the time step and the hold-up were not made for",
             command=typed("periodic", "fill.in"), files={"fill.in": fill(d_mean=1e-3)}),
    BadInput("typed.periodic.fill-for-other-psd", ("psd_sigma = 0.2", "not for this run with", "--psd-sigma 0.05"),
             why="the sweep's PSD variation needs its own fill, not the reference's",
             command=typed("periodic", "fill.in"), files={"fill.in": fill(psd_sigma=0.2)}),
    BadInput("typed.periodic.run-for-other-d_mean", ("made for d_mean = 0.0004", "this run with d_mean = 0.001", "--d-mean 0.001"),
             why="-var d_mean with the default (400 um) fill: the particle-size series needs a fill per size",
             command=typed("periodic", "fill.in", "-var", "d_mean", "0.001"), files={"fill.in": fill()}),
    BadInput("typed.periodic.fill-of-other-meshes", ("domain_length = 0.1125", "domain_length = 0.0958333333333"),
             why="a fill placed in other meshes (another domain length) overlaps these screws",
             command=typed("periodic", "fill.in"), files={"fill.in": fill(length=0.1125)}),
    BadInput("typed.periodic.fill-missing", ("Cannot open input script missing.in", "python -m tsg_cases.prepared fill"),
             why="the fill ./tsg setup makes is missing (set-up not run) or the path is wrong",
             command=typed("periodic", "missing.in")),
    BadInput("typed.full.feed-for-other-d_mean",
             ("feed_file = feed.in was made for d_mean = 0.001", "python -m tsg_cases.prepared feed",
              "--d-mean 0.0004 --feed-at element:7", "and run with -var feed_file"),
             why="feed cubes sized for other particles (the edge is 2.4 x d_mean)",
             command=typed("full", "feed.in"), files={"feed.in": feed(1e-3, 0.5, "element:7")}),
    BadInput("typed.nonperiodic.feed-of-full", ("made for d_mean = 0.0004, domain_length = 0.5", "domain_length = 0.1125"),
             why="the full machine's feed regions in the non-periodic sub-domain",
             command=typed("nonperiodic", "feed.in"), files={"feed.in": feed(4e-4, 0.5, "element:7")}),
    BadInput("typed.prepared.no-meshes", ("--mesh-dir", "no zones.txt", "python -m tsg_meshes build"),
             why="the fill needs the meshes it is placed in",
             command=[*PREPARED, "fill", "{tmp}/out.in", "--mesh-dir", "{tmp}/nothing"]),
    BadInput("typed.prepared.feed-at", ("--feed-at element:99", "1 <= N <= 8"),
             why="the feed must be at the inlet or at an element of the barrel",
             command=[*PREPARED, "feed", "{tmp}/out.in", "--mesh-dir", str(MESHES["nonperiodic"]), "--feed-at", "element:99"]),
    BadInput("typed.prepared.d-mean", ("--d-mean", "0 is not allowed: must be > 0"),
             why="a particle size that no fill can have",
             command=[*PREPARED, "fill", "{tmp}/out.in", "--mesh-dir", str(MESHES["periodic"]), "--d-mean", "0"]),
]
