"""ParaView (pvpython / pvbatch) script for the VTK output of a wetdem many-particle run:
opens the run's .vtk.series indexes in ParaView, checks what ParaView reads, and renders a
frame: the spheres (Glyph, scale array radius, factor 2) coloured by a point array, and, when
the run wrote links, beside them the force network (each contact and bridge as a tube
coloured by its normal force). The recipe of docs/many.md (section "Outputs (`--out DIR`)",
its "ParaView" paragraph), as a script to adapt.

    xvfb-run -a pvbatch tools/paraview_render.py RUN_DIR --png OUT.png
        [--color ARRAY] [--time T] [--check-only]

xvfb-run gives pvbatch the X display that Debian's ParaView renders into (Debian packages
paraview and xvfb; `make paraview` installs them and runs this script on the settling
example). Without --png, or with --check-only, nothing is rendered and pvpython needs no
display.

Checks (exit 1 when one fails): ParaView opens every *.vtk.series of RUN_DIR as one source
with as many time steps as the index lists, at the index's times; at the first and last step
it gives POLYDATA with the arrays of docs/many.md (point arrays for frames, cell arrays for
links), one vertex a particle and two points a link.
"""
import argparse
import os
import sys

from paraview.simple import (AssignViewToLayout, Clip, ColorBy, CreateLayout, CreateView,
                             ExtractSurface, GetColorTransferFunction, GetScalarBar, Glyph,
                             OpenDataFile, Render, SaveScreenshot, Show, Tube, UpdatePipeline,
                             servermanager)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from wetdem_vtk import LINK_ARRAYS, POINT_ARRAYS, read_series  # noqa: E402


def check(index):
    """Opens the index in ParaView; returns (source, its times, its failures)."""
    failures = []
    listed = [t for t, _ in read_series(index)]
    src = OpenDataFile(index)
    times = list(src.TimestepValues) if len(listed) > 1 else listed
    if times != listed:
        failures.append(f"{index}: ParaView sees times {times[:3]}... ({len(times)}), the index "
                        f"lists {listed[:3]}... ({len(listed)})")
    links = index.endswith("_links.vtk.series")
    for t in sorted({listed[0], listed[-1]}):
        UpdatePipeline(time=t, proxy=src)
        d = servermanager.Fetch(src)
        data = d.GetCellData() if links else d.GetPointData()
        names = [data.GetArrayName(k) for k in range(data.GetNumberOfArrays())]
        want = list(LINK_ARRAYS if links else POINT_ARRAYS)
        if d.GetClassName() != "vtkPolyData" or names != want:
            failures.append(f"{index} at t = {t}: {d.GetClassName()} with {names}, expected "
                            f"vtkPolyData with {want}")
        elif links and d.GetNumberOfPoints() != 2 * d.GetNumberOfCells():
            failures.append(f"{index} at t = {t}: {d.GetNumberOfCells()} links with "
                            f"{d.GetNumberOfPoints()} points")
        elif not links and d.GetNumberOfPoints() != d.GetNumberOfCells():
            failures.append(f"{index} at t = {t}: {d.GetNumberOfPoints()} particles with "
                            f"{d.GetNumberOfCells()} vertices")
    kind = "links files" if links else "frames"
    print(f"  ParaView opens {index}: {len(times)} time steps of {kind}, "
          f"{'the expected arrays' if not failures else 'FAILED'}")
    return src, times, failures


def side_view(view, size, bounds):
    """Looks along +y at the spheres' bounds (x to the right, z up) on white, in parallel
    projection, with their face in the left part of the view and room for the colour bar on
    the right."""
    view.ViewSize = size
    view.OrientationAxesVisibility = 0
    view.CameraParallelProjection = 1
    x0, x1, y0, y1, z0, z1 = bounds
    half_h = 0.54 * max(z1 - z0, (x1 - x0) * size[1] / (size[0] - 160))  # (160 px: the bar)
    half_w = half_h * size[0] / size[1]
    cx = x0 - 0.04 * (x1 - x0) + half_w  # the left edge just outside the spheres
    view.CameraFocalPoint = [cx, 0.5 * (y0 + y1), 0.5 * (z0 + z1)]
    view.CameraPosition = [cx, y0 - 10 * (y1 - y0 + z1 - z0), 0.5 * (z0 + z1)]
    view.CameraViewUp = [0, 0, 1]
    view.CameraParallelScale = half_h
    view.Background = [1, 1, 1]
    try:  # (ParaView >= 5.10: the palette's background otherwise)
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass


def colour_bar(lut, view, title):
    bar = GetScalarBar(lut, view)
    bar.Title, bar.ComponentTitle = title, ""
    bar.TitleColor = bar.LabelColor = [0, 0, 0]
    bar.TitleFontSize, bar.LabelFontSize = 18, 16
    bar.RangeLabelFormat = "%-#6.3g"
    bar.WindowLocation = "Any Location"
    bar.Position = [0.8, 0.1]
    bar.ScalarBarLength = 0.5
    bar.Visibility = 1


def render(frames, links, t, color, png, slab):
    """The spheres at time t coloured by `color` and, with links, the force network beside
    them (the links that start within `slab` of the front face, whole), in one image."""
    size = [760, 640]
    v = CreateView("RenderView")
    v.ViewTime = t
    g = Glyph(Input=frames, GlyphType="Sphere")
    g.ScaleArray = ["POINTS", "radius"]
    g.ScaleFactor = 2.0
    g.GlyphMode = "All Points"
    g.GlyphType.ThetaResolution = 16
    g.GlyphType.PhiResolution = 16
    d = Show(g, v)
    ColorBy(d, ("POINTS", color, "Magnitude"))
    d.RescaleTransferFunctionToDataRange(False, True)
    colour_bar(GetColorTransferFunction(color), v, f"{color} (t = {t:.4g} s)")
    views = [v]
    if links is not None:
        w = CreateView("RenderView")
        w.ViewTime = t
        clip = Clip(Input=links)  # (whole lines: Crinkle)
        clip.ClipType = "Plane"
        clip.Crinkleclip = 1
        clip.Invert = 1
        UpdatePipeline(time=t, proxy=frames)
        y0 = frames.GetDataInformation().GetBounds()[2]
        clip.ClipType.Origin = [0, y0 + slab, 0]
        clip.ClipType.Normal = [0, 1, 0]
        tube = Tube(Input=ExtractSurface(Input=clip))  # (Tube takes POLYDATA)
        tube.Radius = 4e-5
        tube.NumberofSides = 8
        e = Show(tube, w)
        ColorBy(e, ("CELLS", "force_normal"))
        lut = GetColorTransferFunction("force_normal")
        lut.ApplyPreset("Cool to Warm", True)
        e.RescaleTransferFunctionToDataRange(False, True)
        span = max(abs(lut.RGBPoints[0]), abs(lut.RGBPoints[-4]))
        lut.RescaleTransferFunction(-span, span)  # white at zero: pull blue, push red
        colour_bar(lut, w, f"force_normal [N], front {slab * 1e3:g} mm")
        views.append(w)
    layout = CreateLayout("wetdem")
    if len(views) == 2:
        layout.SplitHorizontal(0, 0.5)
    for k, view in enumerate(views):
        AssignViewToLayout(view=view, layout=layout, hint=k + 1 if len(views) == 2 else 0)
        Render(view)  # (the first render resets the camera: the side view is set after it)
    bounds = g.GetDataInformation().GetBounds()
    for view in views:
        side_view(view, size, bounds)  # the links in the frame of the spheres
        Render(view)
    SaveScreenshot(png, layout, ImageResolution=[size[0] * len(views), size[1]])
    return [png]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", help="run directory (wetdem run ... --out RUN_DIR)")
    ap.add_argument("--png", help="image to write")
    ap.add_argument("--color", default="velocity", help="point array of the spheres' colour")
    ap.add_argument("--time", type=float, help="time of the frame [s] (default: the last)")
    ap.add_argument("--slab", type=float, default=3e-3,
                    help="depth of the front slab whose links are drawn [m] (default 3e-3)")
    ap.add_argument("--check-only", action="store_true", help="check, render nothing")
    a = ap.parse_args()
    indexes = sorted(f for f in os.listdir(a.run) if f.endswith(".vtk.series"))
    if not indexes:
        sys.exit(f"paraview_render: no .vtk.series in {a.run}")
    failures, sources = [], {}
    for name in indexes:
        src, times, bad = check(os.path.join(a.run, name))
        failures += bad
        sources[name] = (src, times)
    if failures:
        print("\n".join(failures), file=sys.stderr)
        sys.exit(1)
    if a.check_only or not a.png:
        return
    frames = [n for n in indexes if not n.endswith("_links.vtk.series")][0]
    src, times = sources[frames]
    t = times[-1] if a.time is None else min(times, key=lambda x: abs(x - a.time))
    link = sources.get(frames.replace(".vtk.series", "_links.vtk.series"))
    for path in render(src, link[0] if link else None, t, a.color, a.png, a.slab):
        print(f"  wrote {path} (t = {t:.6g} s)")


if __name__ == "__main__":
    main()
