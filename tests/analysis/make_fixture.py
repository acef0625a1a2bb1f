"""Write a small synthetic run directory in exactly the output formats of docs/measurement.md.

    python tests/analysis/make_fixture.py <run_dir> [--kind periodic|full] [--not-steady] [--dumps txt|vtk|none]

Known answers the tests rely on (see FixtureTruth): residence times drawn from Gamma(TANKS,
MEAN_RESIDENCE/TANKS); per-type element values constant over time; mass-flow sensors at FEED_KG_H
once steady. The record starts at RECORD_START (a restarted run) so that every residence time that
matters fits between the first entries and the start of the steady window.
"""
from __future__ import annotations

import argparse
import io
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

DT = 5.0e-7  # s per step
RECORD_START = 1.0  # s: massflow/elements/dumps cover [RECORD_START, RECORD_END]
RECORD_END = 2.0
STEADY_FROM = 1.2  # s: the outlet sensor matches the inlet from here on (steady fixtures)
FEED_KG_H = 14.4
MEAN_RESIDENCE = 0.4  # s
TANKS = 8.0
CENTRE_DISTANCE = 19.31e-3
ROOT_RADIUS = 6.9e-3
BORE_RADIUS = 12.5e-3
FREE_AREA = 435.26e-6  # m^2
DENSITY = 1263.0
RPM = 600.0  # params.json of the fixture: one revolution (the steady-state window) is 0.1 s
D_MEAN = 4.0e-4
ELEMENT_VALUES = {  # solid_fraction, mean_speed, mean_axial_velocity per element type
    "conveying": (0.10, 0.45, 0.25),
    "kneading": (0.30, 0.80, 0.08),
    "chopping": (0.05, 0.60, 0.20),
}
LAYOUTS = {  # (type, length in mm), upstream to downstream
    "periodic": [("conveying", 29.167)] + [("kneading", 6.25)] * 6 + [("conveying", 29.167)],
    "full": [("conveying", 50.0)] + [("kneading", 6.25)] * 6 + [("conveying", 37.5)] + [("kneading", 6.25)] * 6
            + [("conveying", 37.5)] + [("chopping", 25 / 6)] * 2,
}


@dataclass(frozen=True)
class FixtureTruth:
    zone_edges: np.ndarray  # m
    records: int
    rtd_records: int  # outlet/pass records that exit inside the steady window


def _zones_text(kind: str) -> tuple[str, list[str], np.ndarray]:
    layout = LAYOUTS[kind]
    edges = np.concatenate([[0.0], np.cumsum([length for _, length in layout])]) / 1000
    lines = ["# synthetic zones (tests/analysis/make_fixture.py)", "# index type x_start_m x_end_m free_volume_m3"]
    for i, (zone_kind, _) in enumerate(layout):
        lines.append(f"{i + 1} {zone_kind} {edges[i]:.10e} {edges[i + 1]:.10e} {FREE_AREA * (edges[i + 1] - edges[i]):.10e}")
    return "\n".join(lines) + "\n", [k for k, _ in layout], edges


def _residence_text(rng: np.random.Generator, kind: str, zone_kinds: list[str], zone_edges: np.ndarray,
                    records: int) -> tuple[str, int]:
    residence = rng.gamma(TANKS, MEAN_RESIDENCE / TANKS, records)
    entry = np.sort(rng.uniform(0.0, RECORD_END, records))
    exit_time = entry + residence
    reason = np.where(exit_time <= RECORD_END, "pass" if kind == "periodic" else "outlet", "inside").astype("<U7")
    still_inside = reason == "inside"
    unlucky = rng.choice(np.flatnonzero(~still_inside), size=6, replace=False)
    reason[unlucky[:3]], reason[unlucky[3:]] = "deleted", "lost"
    # split each residence time over the zones, crossed in order: kneading zones hold particles 3x
    # longer per length
    weights = np.diff(zone_edges) * np.where(np.array(zone_kinds) == "kneading", 3.0, 1.0)
    shares = rng.dirichlet(200 * weights / weights.sum(), records)
    by_zone = residence[:, None] * shares
    # a particle still inside at RECORD_END (a snapshot record) has crossed its zones up to then
    exit_time[still_inside] = RECORD_END
    residence[still_inside] = RECORD_END - entry[still_inside]
    before = np.cumsum(by_zone, axis=1) - by_zone
    by_zone[still_inside] = np.clip(residence[still_inside, None] - before[still_inside], 0.0, by_zone[still_inside])
    by_type = [by_zone[:, np.array(zone_kinds) == t].sum(axis=1) for t in ("conveying", "kneading", "chopping")]
    table = np.column_stack([np.arange(1, records + 1), entry, exit_time, residence, np.zeros(records), *by_type, by_zone])
    buffer = io.StringIO()
    np.savetxt(buffer, table, fmt=["%d", *["%.9g"] * 3, "%d", *["%.9g"] * (3 + len(zone_kinds))])
    rows = buffer.getvalue().splitlines()
    rows = [_with_reason(row, r) for row, r in zip(rows, reason)]
    header = ["# tsg-dem residence records v1", f"# run kind {kind}, synthetic",
              "# columns: id entry_time exit_time residence_time exit_reason time_conveying time_kneading "
              "time_chopping " + " ".join(f"time_zone_{i}" for i in range(1, len(zone_kinds) + 1))]
    rtd = int(np.count_nonzero(np.isin(reason, ("pass", "outlet")) & (exit_time > STEADY_FROM)))
    return "\n".join(header + rows) + "\n", rtd


def _with_reason(row: str, reason: str) -> str:
    """Put the exit reason word in place of its placeholder column (fixture-sized loop)."""
    words = row.split(" ")
    words[4] = reason
    return " ".join(words)


def _flow_fill(time: np.ndarray, steady: bool) -> np.ndarray:
    """Outlet flow over inlet flow: 1 from STEADY_FROM on when steady; stuck at one half when not."""
    ramp = np.clip((time - RECORD_START) / (STEADY_FROM - RECORD_START), 0.0, 1.0)
    return ramp if steady else 0.5 * ramp


def _massflow_text(rng: np.random.Generator, steady: bool, sensors: int) -> str:
    time = np.arange(RECORD_START + 1e-3, RECORD_END + 1e-9, 1e-3)
    fill = _flow_fill(time, steady)
    noise = rng.normal(0.0, 0.5, (sensors, len(time)))  # sensor noise, kg/h
    columns = [FEED_KG_H + noise[0]]
    for k in range(1, sensors):
        share = k / (sensors - 1)  # sensors further downstream lag more during the start-up
        columns.append(FEED_KG_H * (1 - share + share * fill) + noise[k])
    table = np.column_stack([np.round(time / DT), time, *columns])
    buffer = io.StringIO()
    np.savetxt(buffer, table, fmt=["%d", "%.6f", *["%.5f"] * sensors])
    header = ["# tsg-dem mass flow v1", "# columns: step time " + " ".join(f"sensor_{k}" for k in range(1, sensors + 1))]
    return "\n".join(header) + "\n" + buffer.getvalue()


def _elements_text(rng: np.random.Generator, zone_kinds: list[str], zone_edges: np.ndarray, steady: bool) -> str:
    lines = ["# Time-averaged data for fix elements", "# TimeStep Number-of-rows",
             "# Row c_zones[1] c_zones[2] c_zones[3] c_zones[4] c_zones[5]"]
    for time in np.arange(RECORD_START + 0.01, RECORD_END + 1e-9, 0.01):
        lines.append(f"{round(time / DT)} {len(zone_kinds)}")
        fill = 1.0 if steady and time > STEADY_FROM else 0.5
        for row, zone_kind in enumerate(zone_kinds, start=1):
            fraction, speed, axial = ELEMENT_VALUES[zone_kind]
            volume = FREE_AREA * (zone_edges[row] - zone_edges[row - 1]) * fraction * fill
            mass = volume * DENSITY
            count = int(rng.integers(50, 150))
            lines.append(f"{row} {fraction * fill:.6g} {speed:.6g} {axial:.6g} {count} {mass:.6g}")
    return "\n".join(lines) + "\n"


def _particles(rng: np.random.Generator, zone_edges: np.ndarray, count: int) -> dict[str, np.ndarray]:
    """Particles in the free space of the twin bore (outside the screw root cylinders)."""
    length = zone_edges[-1]
    y = np.empty(0)
    z = np.empty(0)
    while len(y) < count:  # rejection sampling, a few vectorised rounds
        cy = rng.uniform(-CENTRE_DISTANCE / 2 - BORE_RADIUS, CENTRE_DISTANCE / 2 + BORE_RADIUS, 4 * count)
        cz = rng.uniform(-BORE_RADIUS, BORE_RADIUS, 4 * count)
        left, right = np.hypot(cy + CENTRE_DISTANCE / 2, cz), np.hypot(cy - CENTRE_DISTANCE / 2, cz)
        keep = ((left < BORE_RADIUS - 3e-4) | (right < BORE_RADIUS - 3e-4)) & (left > ROOT_RADIUS) & (right > ROOT_RADIUS)
        y, z = np.concatenate([y, cy[keep]]), np.concatenate([z, cz[keep]])
    return {"id": np.arange(1, count + 1), "type": np.ones(count, np.int64), "x": rng.uniform(0, length, count),
            "y": y[:count], "z": z[:count], "radius": rng.uniform(1.8e-4, 2.2e-4, count)}


def _write_dumps(rng: np.random.Generator, dumps_dir: Path, kind: str, fmt: str, zone_kinds: list[str],
                 zone_edges: np.ndarray, frames: int, count: int) -> None:
    dumps_dir.mkdir(parents=True, exist_ok=True)
    particles = _particles(rng, zone_edges, count)
    length = zone_edges[-1]
    zone_of = np.clip(np.searchsorted(zone_edges, particles["x"], side="right") - 1, 0, len(zone_kinds) - 1)
    vx = np.array([ELEMENT_VALUES[k][2] for k in zone_kinds])[zone_of]
    times = np.linspace(RECORD_END - 0.1, RECORD_END, frames)
    mass = DENSITY * 4 / 3 * np.pi * particles["radius"] ** 3
    for frame, time in enumerate(times):
        x = particles["x"] + vx * (time - times[0])
        if kind == "periodic":
            x %= length
        kept = x < length  # the full granulator's outlet deletes what leaves
        velocity = np.column_stack([vx, rng.normal(0, 0.3, count), rng.normal(0, 0.3, count)])[kept]
        step = round(time / DT)
        if fmt == "vtk":  # no mass column: the report then needs --density
            import pyvista as pv

            cloud = pv.PolyData(np.column_stack([x, particles["y"], particles["z"]])[kept])
            cloud.point_data["id"] = particles["id"][kept]
            cloud.point_data["type"] = particles["type"][kept]
            cloud.point_data["v"] = velocity
            cloud.point_data["radius"] = particles["radius"][kept]
            cloud.save(dumps_dir / f"particles_{step}.vtk", binary=frame % 2 == 0)
            continue
        flags = "pp ff ff" if kind == "periodic" else "ff ff ff"
        half_y = CENTRE_DISTANCE / 2 + BORE_RADIUS
        head = (f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{np.count_nonzero(kept)}\nITEM: BOX BOUNDS {flags}\n"
                f"0 {length:.10e}\n{-half_y:.6e} {half_y:.6e}\n{-BORE_RADIUS:.6e} {BORE_RADIUS:.6e}\n"
                "ITEM: ATOMS id type x y z vx vy vz radius mass\n")
        table = np.column_stack([particles["id"], particles["type"], x, particles["y"], particles["z"]])[kept]
        table = np.column_stack([table, velocity, particles["radius"][kept], mass[kept]])
        buffer = io.StringIO()
        np.savetxt(buffer, table, fmt=["%d", "%d", *["%.8g"] * 8])
        (dumps_dir / f"particles_{step}.txt").write_text(head + buffer.getvalue())


def _write_meshes(meshes_dir: Path, length: float) -> None:
    import pyvista as pv

    meshes_dir.mkdir(parents=True, exist_ok=True)
    for name, y in (("screw1.stl", -CENTRE_DISTANCE / 2), ("screw2.stl", CENTRE_DISTANCE / 2)):
        screw = pv.Cylinder(center=(length / 2, y, 0.0), direction=(1, 0, 0), radius=ROOT_RADIUS, height=length,
                            resolution=24)
        screw.triangulate().save(meshes_dir / name)


def _log_text(particles: int, warnings: bool) -> str:
    lines = ["LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0 + tsg-dem 0.1.0)",
             "Created orthogonal box = (0 -0.0221 -0.0125) to (0.0958 0.0221 0.0125)",
             "    Step    Atoms         KinEng            CPU "]
    for step in range(0, 4_000_001, 1_000_000):
        lines.append(f"{step:8d} {particles:8d} {1e-5 * (1 + step / 4e6):14.7g} {step / 1e5:14.7g} ")
    if warnings:
        lines.append("WARNING: Particle insertion: Less insertions than requested (../fix_insert.cpp:740)")
    lines.append(f"Loop time of 40 on 1 procs for 4000000 steps with {particles} atoms")
    return "\n".join(lines) + "\n"


def _params(kind: str, seed: int, rpm: float) -> dict:
    """What the case runner records in params.json (the contract in docs/measurement.md)."""
    return {"case": kind, "scale": "synthetic", "seed": seed, "np": 1,
            "variables": {"rpm": f"{rpm:g}", "rho_p": f"{DENSITY:g}", "d_mean": f"{D_MEAN:g}"},
            "rpm": rpm, "rho_p": DENSITY, "d_mean": D_MEAN, "mesh_dir": "meshes", "zones_file": "zones.txt",
            "git_commit": "synthetic"}


def write_run(run_dir: Path | str, *, kind: str = "periodic", steady: bool = True, dumps: str | None = "txt",
              meshes: bool = True, records: int = 4000, frames: int = 5, particles: int = 1500,
              seed: int = 1, rpm: float = RPM) -> FixtureTruth:
    """Write a complete run directory; return what the tests should find in it."""
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    zones, zone_kinds, zone_edges = _zones_text(kind)
    (run_dir / "zones.txt").write_text(zones)
    residence, rtd_records = _residence_text(rng, kind, zone_kinds, zone_edges, records)
    (run_dir / "residence.txt").write_text(residence)
    (run_dir / "elements.txt").write_text(_elements_text(rng, zone_kinds, zone_edges, steady))
    (run_dir / "massflow.txt").write_text(_massflow_text(rng, steady, 2 if kind == "periodic" else 3))
    (run_dir / "log.lammps").write_text(_log_text(particles, warnings=not steady))
    (run_dir / "params.json").write_text(json.dumps(_params(kind, seed, rpm), indent=1))
    if dumps is not None:
        _write_dumps(rng, run_dir / "dumps", kind, dumps, zone_kinds, zone_edges, frames, particles)
    if meshes:
        _write_meshes(run_dir / "meshes", zone_edges[-1])
    return FixtureTruth(zone_edges, records, rtd_records)


def write_short_run(run_dir: Path | str, seconds: float = 0.03, every: int = 5, seed: int = 5) -> None:
    """The main job's situation (issue 15): a periodic run whose sampling window is far shorter than
    one pass. A periodic run cut to its first `seconds` of records, with every `every`-th
    mass-flow row (5 ms windows as the demo scale writes) and no complete residence record."""
    run_dir = Path(run_dir)
    write_run(run_dir, kind="periodic", dumps=None, meshes=False, seed=seed)
    end = RECORD_START + seconds + 1e-9
    flow_lines = (run_dir / "massflow.txt").read_text().splitlines()
    header = [line for line in flow_lines if line.startswith("#")]
    rows = [line for line in flow_lines if not line.startswith("#") and float(line.split()[1]) <= end]
    (run_dir / "massflow.txt").write_text("\n".join(header + rows[every - 1::every]) + "\n")
    element_lines = (run_dir / "elements.txt").read_text().splitlines()
    zones = len(LAYOUTS["periodic"])
    kept = element_lines[:3]
    for start in range(3, len(element_lines), zones + 1):
        if int(element_lines[start].split()[0]) * DT <= end:
            kept += element_lines[start:start + zones + 1]
    (run_dir / "elements.txt").write_text("\n".join(kept) + "\n")
    residence_header = [line for line in (run_dir / "residence.txt").read_text().splitlines() if line.startswith("#")]
    (run_dir / "residence.txt").write_text("\n".join(residence_header) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("--kind", choices=sorted(LAYOUTS), default="periodic")
    parser.add_argument("--not-steady", action="store_true")
    parser.add_argument("--dumps", choices=("txt", "vtk", "none"), default="txt")
    args = parser.parse_args()
    write_run(args.run_dir, kind=args.kind, steady=not args.not_steady,
              dumps=None if args.dumps == "none" else args.dumps)


if __name__ == "__main__":
    main()
