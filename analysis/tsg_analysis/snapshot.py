"""Particle snapshot coloured by longitudinal velocity, screws drawn (seed Fig. 11), rendered
off-screen with pyvista.

The screws are drawn in the pose the run itself wrote at the frame's step (`dumps/screws_*<step>.vtk`:
fix wall/gran/corotating's `screw_dump`, or the stock `dump mesh/vtk`), never rebuilt from rpm × t.
Without such dumps the STL files are drawn as built and the caption says the pose is unknown.
Files whose name contains "barrel" are drawn translucent.
"""
from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .dumps import ParticleFrame, step_from_name
from .run_files import AnalysisInputError


def screw_dumps_at(run_dir: Path, step: int) -> list[Path]:
    """The screw surfaces the run dumped at `step` (dumps/screws_*<step>.vtk), in name order."""
    candidates = sorted((Path(run_dir) / "dumps").glob(f"screws_*{step}.vtk"))
    return [path for path in candidates if step_from_name(path) == step]


def render_snapshot(frame: ParticleFrame, out_png: Path, mesh_paths: Sequence[Path] = (),
                    time: float | None = None, posed: bool = False,
                    window_size: tuple[int, int] = (1600, 700)) -> Path:
    """Top view (looking down −z) of the particles of one frame, coloured by vx. `posed`: the meshes
    are in their pose at the frame's step (screw dumps), not as built."""
    import pyvista as pv  # heavy import: only the snapshot needs VTK rendering

    frame.require("x", "y", "z", "vx")
    pv.OFF_SCREEN = True
    points = np.column_stack([frame.columns["x"], frame.columns["y"], frame.columns["z"]])
    cloud = pv.PolyData(points)
    cloud.point_data["vx (m/s)"] = frame.columns["vx"]
    limit = float(np.percentile(np.abs(frame.columns["vx"]), 98)) or 1.0
    plotter = pv.Plotter(off_screen=True, window_size=list(window_size))
    plotter.set_background("white")  # type: ignore[arg-type]  # pyvista's decorator stub hides `self`
    for path in mesh_paths:
        try:
            mesh = pv.read(path)
        except Exception as err:  # VTK reports damaged files with assorted exception types
            raise AnalysisInputError(f"{path}: cannot be read as a mesh ({err})") from None
        if not isinstance(mesh, pv.DataSet):
            raise AnalysisInputError(f"{path}: holds a {type(mesh).__name__}, not a surface mesh")
        if "barrel" in Path(path).name:
            plotter.add_mesh(mesh, color="lightgrey", opacity=0.12)
            continue
        plotter.add_mesh(mesh, color="silver", smooth_shading=True)
    plotter.add_mesh(cloud, scalars="vx (m/s)", cmap="coolwarm", clim=(-limit, limit),
                     render_points_as_spheres=True, point_size=_point_size(len(points)),
                     scalar_bar_args={"title": "longitudinal velocity vx (m/s)", "color": "black"})
    caption = f"step {frame.step}" + ("" if time is None else f", t = {time:.4g} s") + f", {len(points)} particles"
    if mesh_paths:
        caption += ", screws as dumped at this step" if posed else ", screws drawn as built (no screw dump: pose unknown)"
    plotter.add_text(caption, font_size=10, color="black")
    plotter.view_xy()  # type: ignore[call-arg]  # pyvista's decorator stub hides `self`
    plotter.camera.zoom(1.3)
    out_png = Path(out_png)
    plotter.screenshot(str(out_png))
    plotter.close()
    return out_png


def _point_size(count: int) -> float:
    """Fewer particles, bigger dots: keeps both a 1 000 and a 1 000 000 particle frame readable."""
    return float(np.clip(12.0 / np.log10(max(count, 10)), 1.5, 8.0))
