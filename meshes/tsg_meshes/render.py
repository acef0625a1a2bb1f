"""PNG renders for docs/geometry.md: each element type, the assembled screws, and a mesh section."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .analysis import section_segments
from .build import DEFAULT_TOLERANCE, BuiltGeometry, generate, resolve_config
from .spec import parse_spec, read_spec
from .surface import TriangleMesh

# coarse enough that single triangles are visible in element close-ups
SHOW_EDGES_TOLERANCE = 2e-5
SCREW_COLOURS = ("#7fb0e0", "#f2a860")


def _polydata(mesh: TriangleMesh):
    import pyvista as pv

    faces = np.column_stack((np.full(len(mesh.triangles), 3), mesh.triangles)).ravel()
    return pv.PolyData(mesh.vertices * 1e3, faces)  # millimetres read better on axes


def _plotter(size=(1200, 700)):
    import pyvista as pv

    pv.OFF_SCREEN = True
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    # pyvista types set_background through functools.wraps of the unbound Renderers method
    plotter.set_background("white")  # type: ignore[arg-type]
    return plotter


def _render_screws(geometry: BuiltGeometry, path: Path, show_edges: bool, screws=(1, 2),
                   barrel: bool = False, camera=None, size=(1200, 700)) -> Path:
    plotter = _plotter(size)
    for screw in screws:
        plotter.add_mesh(_polydata(geometry.screws[screw - 1]), color=SCREW_COLOURS[screw - 1],
                         show_edges=show_edges, edge_color="#203040", line_width=0.5,
                         smooth_shading=not show_edges, ambient=0.25)
    if barrel:
        # lower half of the barrel only, so that the screws stay visible
        lower = _polydata(geometry.barrel).clip(normal="z", origin=(0, 0, 0))
        plotter.add_mesh(lower, color="#b0b0b0", opacity=0.45, smooth_shading=True)
    plotter.add_axes(xlabel="x", ylabel="y", zlabel="z")
    plotter.camera_position = camera or "iso"
    if camera is None:
        plotter.camera.azimuth = -30
        plotter.camera.elevation = 10
    plotter.reset_camera()
    plotter.camera.zoom(1.3 if camera is None else 4.0 if size[0] > 1500 else 1.5)
    plotter.screenshot(str(path))
    plotter.close()
    return path


def _element_geometry(elements: str) -> BuiltGeometry:
    return generate(parse_spec(f"name render\nends inlet-wall\nelements {elements}\n"), SHOW_EDGES_TOLERANCE)


def _section_plot(geometry: BuiltGeometry, x: float, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    figure, axes = plt.subplots(figsize=(8, 4.6))
    for mesh, colour in zip((*geometry.screws, geometry.barrel), (*SCREW_COLOURS, "#505050")):
        segments = section_segments(mesh.corners, x) * 1e3  # (n, 2, 2) array: matplotlib's stubs want a Sequence
        axes.add_collection(LineCollection(segments, colors=colour, linewidths=1.0))  # type: ignore[arg-type]
    axes.set_xlim(-23, 23)
    axes.set_ylim(-13.5, 13.5)
    axes.set_aspect("equal")
    axes.set_xlabel("y [mm]")
    axes.set_ylabel("z [mm]")
    axes.set_title(f"{geometry.configuration.name}: mesh section at x = {x * 1e3:.2f} mm\n"
                   "seen from the outlet (+x towards the viewer): screw 1 left, screw 2 right, "
                   "both turning counter-clockwise", fontsize=9)
    figure.tight_layout()
    figure.savefig(path, dpi=130)
    plt.close(figure)
    return path


def render_all(imgdir: Path | str) -> list[Path]:
    imgdir = Path(imgdir)
    imgdir.mkdir(parents=True, exist_ok=True)
    written = []
    for name, elements in (("element-conveying-C1.5", "C1.5"), ("element-kneading-disc", "K1"),
                           ("element-kneading-block-K6x60R", "K6x60R"), ("element-chopping-CH2x60R", "CH2x60R")):
        written.append(_render_screws(_element_geometry(elements), imgdir / f"{name}.png", show_edges=True,
                                      screws=(1,), size=(900, 700)))
    written.append(_render_screws(_element_geometry("C1/2 K6x60R C1/2"), imgdir / "element-block-faces.png",
                                  show_edges=True, screws=(1,), size=(1100, 700),
                                  camera=[(60, -40, 30), (25, -9.655, 0), (0, 0, 1)]))
    for config in ("consigma1-periodic", "consigma1-nonperiodic", "consigma1-full"):
        geometry = generate(read_spec(resolve_config(config)), DEFAULT_TOLERANCE)
        length_mm = geometry.length * 1e3
        # the 500-mm screw is seen from the side and above, x across the picture
        camera = [(length_mm / 2, -2.2 * length_mm, 1.2 * length_mm), (length_mm / 2, 0, 0), (0, 0, 1)] \
            if config == "consigma1-full" else None
        size = (1800, 420) if config == "consigma1-full" else (1200, 650)
        written.append(_render_screws(geometry, imgdir / f"assembled-{config}.png", show_edges=False,
                                      barrel=True, size=size, camera=camera))
        if config == "consigma1-periodic":
            kneading = [e for e in geometry.configuration.elements if e.kind == "kneading"][2]
            x = float(kneading.x_start_mm) / 1000 + 0.4127 * float(kneading.length_mm) / 1000
            written.append(_section_plot(geometry, x, imgdir / "section-periodic-kneading.png"))
    return written
