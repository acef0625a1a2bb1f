"""Particle snapshot coloured by longitudinal velocity, screws drawn (seed Fig. 11), rendered
off-screen with pyvista.

The screw STL files are as built (phase 0); when the screw speed and the frame time are known
they are turned to where they were at that time: both screws co-rotate with ω > 0 about +x, each
about its own axis (zones.txt header). Files whose name contains "barrel" are drawn translucent.
"""
from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .cross_section import CENTRE_DISTANCE
from .dumps import ParticleFrame
from .run_files import AnalysisInputError


def render_snapshot(frame: ParticleFrame, out_png: Path, mesh_paths: Sequence[Path] = (),
                    time: float | None = None, screw_rpm: float | None = None,
                    window_size: tuple[int, int] = (1600, 700)) -> Path:
    """Top view (looking down −z) of the particles of one frame, coloured by vx."""
    import pyvista as pv  # heavy import: only the snapshot needs VTK rendering

    frame.require("x", "y", "z", "vx")
    pv.OFF_SCREEN = True
    points = np.column_stack([frame.columns["x"], frame.columns["y"], frame.columns["z"]])
    cloud = pv.PolyData(points)
    cloud.point_data["vx (m/s)"] = frame.columns["vx"]
    limit = float(np.percentile(np.abs(frame.columns["vx"]), 98)) or 1.0
    plotter = pv.Plotter(off_screen=True, window_size=list(window_size))
    plotter.set_background("white")
    angle = None if time is None or screw_rpm is None else 360.0 * screw_rpm / 60.0 * time
    for path in mesh_paths:
        try:
            mesh = pv.read(path)
        except Exception as err:  # VTK reports damaged files with assorted exception types
            raise AnalysisInputError(f"{path}: cannot be read as a mesh ({err})") from None
        if "barrel" in Path(path).name:
            plotter.add_mesh(mesh, color="lightgrey", opacity=0.12)
            continue
        if angle is not None:  # each screw turns about its own axis, the one on its side of y = 0
            axis_y = np.copysign(CENTRE_DISTANCE / 2, mesh.center[1])
            mesh = mesh.rotate_x(angle, point=(0.0, axis_y, 0.0))
        plotter.add_mesh(mesh, color="silver", smooth_shading=True)
    plotter.add_mesh(cloud, scalars="vx (m/s)", cmap="coolwarm", clim=(-limit, limit),
                     render_points_as_spheres=True, point_size=_point_size(len(points)),
                     scalar_bar_args={"title": "longitudinal velocity vx (m/s)", "color": "black"})
    caption = f"step {frame.step}" + ("" if time is None else f", t = {time:.4g} s") + f", {len(points)} particles"
    if mesh_paths and angle is None:
        caption += ", screws drawn as built (rotation unknown)"
    plotter.add_text(caption, font_size=10, color="black")
    plotter.view_xy()
    plotter.camera.zoom(1.3)
    out_png = Path(out_png)
    plotter.screenshot(str(out_png))
    plotter.close()
    return out_png


def _point_size(count: int) -> float:
    """Fewer particles, bigger dots: keeps both a 1 000 and a 1 000 000 particle frame readable."""
    return float(np.clip(12.0 / np.log10(max(count, 10)), 1.5, 8.0))
